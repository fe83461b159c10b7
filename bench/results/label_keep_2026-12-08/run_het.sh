#!/usr/bin/env bash
# The heterogeneous phantom (1000 Pa fat, gland 2x, tumours 10x, quadratic truth, prone) through
# its label map, against its own scene, with the default plan (E estimated where the label scene
# is written so, as its own scene is). Its label map's tumours are now the tumour spheres, not the
# generator's stiff tumour tetrahedra, so the label scenes have the phantom's 5 tumours.
# Usage: bash run_het.sh OUT
set -uo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
B="$REPO/build/ws/devel/lib/breast_tumour_registration"; OUT="$1"
export OMP_NUM_THREADS=1
mkdir -p "$OUT"; rm -f "$OUT/rows.txt"
[ -d "$OUT/het" ] || "$B/btr_phantom" -q -o "$OUT/het/phantom" --cell-size 8 --youngs-modulus 1000 --gland-youngs-modulus 2000 \
  --tumour-youngs-modulus 10000 --element-order quadratic --label-map "$OUT/het/labels" > /dev/null
L="$OUT/het/labels"
printf "fat: [1]\ngland: [2]\ntumour: [3]\nmuscle: 4\nstiffness: {gland: 2, tumour: 10}\n" > "$L/labels.yaml"
summary() {
  /usr/bin/python3 -c "
import json
r=json.load(open('$1'))
t=[x for x in r['tumours'] if x.get('centroid_distance_mm') is not None]
print('tumours=%d with_truth=%d tets=%d errors=%s worst=%.3f converged=%s' % (len(r['tumours']), len(t), r['mesh']['tetrahedra'], ' '.join('%.3f' % x['centroid_distance_mm'] for x in t), max(x['centroid_distance_mm'] for x in t), r.get('converged')))" 2>/dev/null || echo "-"
}
truth=(); for t in top middle bottom left right; do truth+=(--truth "$t,$L/tumour_${t}_prone.obj,$L/tumour_${t}_supine.obj"); done
grep -q "youngs_modulus: estimate" "$OUT/het/phantom/scene.yaml" && est=1 || est=0
"$B/btr_register" "$OUT/het/phantom/scene.yaml" -q -o "$OUT/own" > "$OUT/own.log" 2>&1
echo "own_scene rc=$? $(summary "$OUT/own/report.json")" | tee -a "$OUT/rows.txt"
for c in 7 9; do
  d="$OUT/labels_c$c"
  "$B/btr_scene_from_labels" "$L/prone_labels.nii.gz" --labels "$L/labels.yaml" --cell-size $c \
    --prone-landmarks "$L/prone_landmarks.mrk.json" --supine-landmarks "$L/supine_landmarks.mrk.json" \
    --supine-surface "$L/supine_surface.obj" "${truth[@]}" -o "$d/scene" > "$d.mesh.log" 2>&1 || { echo "labels_c$c mesh failed"; continue; }
  [ $est = 1 ] && sed -i 's/^  youngs_modulus: [0-9.]*$/  youngs_modulus: estimate/' "$d/scene/scene.yaml"
  "$B/btr_register" "$d/scene/scene.yaml" -q -o "$d/reg" > "$d/reg.log" 2>&1
  echo "labels_c$c rc=$? $(summary "$d/reg/report.json")" | tee -a "$OUT/rows.txt"
done
