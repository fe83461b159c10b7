cd /work/main
run() { name=$1; shift; { echo "== $name $*"; OMP_NUM_THREADS=1 /tmp/fallback_mesh "$@" 2>&1 | grep -v "^\[" ; } > /tmp/fb/$name.log; }
export -f run
cat <<L | xargs -P 2 -L 1 bash -c 'run "$@"' _
S1_1000_aligned test/data/independent_truth_E1000/scene_estimated_regions.yaml
S1_1000_mis test/data/independent_truth_E1000/scene_estimated_regions.yaml 15 10
S1_3400_mis test/data/independent_truth_E3400/scene_estimated_regions.yaml 15 10
S2_500_aligned /tmp/front/B/E500/scene_estimated_regions.yaml
S2_500_mis /tmp/front/B/E500/scene_estimated_regions.yaml 15 10
S2_1000_mis /tmp/front/B/E1000/scene_estimated_regions.yaml 15 10
P400_aligned /tmp/front/ph400/scene_est.yaml
P400_mis /tmp/front/ph400/scene_est.yaml 15 10
L
echo done > /tmp/fb/DONE
