#!/bin/bash
# btr_register as a user runs it: the default (balanced) against the same scene with the element form stated
B=/work/main/build/ws/devel/lib/breast_tumour_registration
for spec in S1_1000=/work/main/test/data/independent_truth_E1000/scene_estimated_regions.yaml S1_3400=/work/main/test/data/independent_truth_E3400/scene_estimated_regions.yaml S2_500=/tmp/front/B/E500/scene_estimated_regions.yaml S2_1000=/tmp/front/B/E1000/scene_estimated_regions.yaml S2_3400=/tmp/front/B/E3400/scene_estimated_regions.yaml P_1000=/tmp/front/ph1000/scene_est.yaml P_400=/tmp/front/ph400/scene_est.yaml; do
  name=${spec%%=*}; scene=${spec#*=}; dir=$(dirname $scene)
  /usr/bin/python3 - "$scene" "$dir/.users_element.yaml" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1])); s.setdefault('material', {})['volume_form'] = 'element'
yaml.safe_dump(s, open(sys.argv[2], 'w'))
PY
  for v in default element; do
    sc=$scene; [ $v = element ] && sc=$dir/.users_element.yaml
    OMP_NUM_THREADS=1 $B/btr_register $sc -q -o /tmp/front/users/${name}_$v > /tmp/front/users/${name}_$v.log 2>&1; echo "exit $?" >> /tmp/front/users/${name}_$v.log
  done
  rm -f $dir/.users_element.yaml
done
echo done > /tmp/front/users/done
