cd /work/main
for T in linear quadratic; do
  ( start=$(date +%s); OMP_NUM_THREADS=1 BTR_CAL_TRUTH_ELEMENTS=$T BTR_CAL_E_MIN=600 BTR_CAL_STIFFNESS=estimate BTR_CAL_DRAWS=3 BTR_CAL_SAMPLES=16 \
    bash bench/run_calibration.sh /tmp/cal/$T phantom > /tmp/cal/$T.log 2>&1; echo "rc=$? seconds=$(( $(date +%s) - start ))" >> /tmp/cal/$T.log ) &
done
wait
echo done > /tmp/cal/DONE
