for E in 1000 3400; do
  OMP_NUM_THREADS=1 btr_calibration test/data/independent_truth_E$E/scene_estimated_regions.yaml --draws 3 --samples 16 -p balanced -o /tmp/cal3/E$E > /tmp/cal3/E$E.log 2>&1; echo "exit $?" >> /tmp/cal3/E$E.log
done
