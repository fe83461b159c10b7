# Mesh chaos (name=scene.yaml arguments, else the four below): the default call's worst tumour error over cell sizes within +-1 % of the preset's.
cd /work/main
B=build/ws/devel/lib/breast_tumour_registration
DEFAULT_SCENES="S1_1000=test/data/independent_truth_E1000/scene_estimated_regions.yaml S1_3400=test/data/independent_truth_E3400/scene_estimated_regions.yaml S2_500=/tmp/front/B/E500/scene_estimated_regions.yaml S2_1000=/tmp/front/B/E1000/scene_estimated_regions.yaml"
for sc in ${@:-$DEFAULT_SCENES}; do
  name=${sc%%=*}; scene=${sc#*=}; dir=$(dirname $scene)
  /usr/bin/python3 - "$scene" "$dir/.ms_element.yaml" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1])); s.setdefault('material', {})['volume_form'] = 'element'
yaml.safe_dump(s, open(sys.argv[2], 'w'))
PY
  for form in nodal element; do
    if [ $form = nodal ]; then f=$scene; cells="8.91 8.955 9 9.045 9.09"; else f=$dir/.ms_element.yaml; cells="6.93 6.965 7 7.035 7.07"; fi
    for c in $cells; do
      out=/tmp/ms/out_${name}_${form}_$c
      OMP_NUM_THREADS=1 $B/btr_register $f --out $out -q --cell-size $c > $out.log 2>&1
      python3 - "$name" "$form" "$c" "$out/report.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[4]))
w = max(t['centroid_distance_mm'] for t in r['tumours']) if 'tumours' in r else float('nan')
print(sys.argv[1], sys.argv[2], sys.argv[3], r['mesh']['vertices'], r['material_model']['volume_form'], round(w, 3), r.get('converged'), flush=True)
PY
    done
  done
  rm -f $dir/.ms_element.yaml
done
echo done
