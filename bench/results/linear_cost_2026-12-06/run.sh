# Linearised uncertainty's cost under the default (balanced: the nodal form where a scene unloads):
# its seconds against the registration's, from report.json, three calls per scene.
cd /work/main
B=build/ws/devel/lib/breast_tumour_registration
for sc in S1_1000=test/data/independent_truth_E1000/scene_estimated_regions.yaml S1_3400=test/data/independent_truth_E3400/scene_estimated_regions.yaml S2_1000=/tmp/front/B/E1000/scene_estimated_regions.yaml P_1000=/tmp/front/ph1000/scene_est.yaml; do
  name=${sc%%=*}; scene=${sc#*=}
  for k in 1 2 3; do
    out=/tmp/lin/out_${name}_$k
    OMP_NUM_THREADS=1 $B/btr_register $scene --out $out -q --uncertainty linear > $out.log 2>&1
    echo "$name $k rc=$? $(grep -o 'registration [0-9.]* s' $out.log) $(grep -o 'linearised in [0-9.]* s' $out.log)"
  done
done
echo done
