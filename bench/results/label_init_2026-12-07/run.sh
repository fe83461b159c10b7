#!/usr/bin/env bash
# The label mesher's initial points, before (make_mesh_3's rays from the image box's centre) and
# after (CGAL's initialisation from each connected component), side by side on the same label
# maps: mesh size and time, and the registered tumours' errors. Each pair runs at once (one
# OpenMP thread each). OLD_LIB is a copy of devel/lib built from 51cdc3a; a side that has not
# finished meshing after LIMIT seconds is stopped and reported as "hung".
# Usage: OLD_LIB=/tmp/oldlab bash run.sh OUT
set -uo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
NEW_LIB="$REPO/build/ws/devel/lib"
OLD_LIB="${OLD_LIB:?a copy of devel/lib built from 51cdc3a}"
OUT="$1"; LIMIT="${LIMIT:-120}"
B="$NEW_LIB/breast_tumour_registration"
export OMP_NUM_THREADS=1
mkdir -p "$OUT"
truth() { for t in top middle bottom left right; do echo --truth "$t,$1/tumour_${t}_prone.obj,$1/tumour_${t}_supine.obj"; done; }
# The bodies: the 8 mm phantom at 1 mm voxels (homogeneous, not prone: the image is the rest
# shape), the 6 mm phantom in a 512 x 512 x 160 MRI field of view, and a heterogeneous quadratic
# 1000 Pa phantom (gland 2x, tumours 10x; prone, unloaded) at 1 mm voxels.
[ -d "$OUT/p8" ] || "$B/btr_phantom" -q -o "$OUT/p8/phantom" --cell-size 8 --label-map "$OUT/p8/labels" > /dev/null
[ -d "$OUT/mri" ] || "$B/btr_phantom" -q -o "$OUT/mri/phantom" --cell-size 6 --label-map "$OUT/mri/labels" --voxel-size 0.7,0.7,1.0 \
  --label-map-voxels 512,512,160 > /dev/null
[ -d "$OUT/het" ] || "$B/btr_phantom" -q -o "$OUT/het/phantom" --cell-size 8 --youngs-modulus 1000 --gland-youngs-modulus 2000 \
  --tumour-youngs-modulus 10000 --element-order quadratic --label-map "$OUT/het/labels" > /dev/null
printf "stiffness: {gland: 1, tumour: 1}\n" > "$OUT/p8/labels/labels.yaml"
printf "stiffness: {gland: 1, tumour: 1}\n" > "$OUT/mri/labels/labels.yaml"
printf "fat: [1]\ngland: [2]\ntumour: [3]\nmuscle: 4\nstiffness: {gland: 2, tumour: 10}\n" > "$OUT/het/labels/labels.yaml"
# one NAME BODY NOT_PRONE CELL_MM STEPS: meshes and registers with both libraries at once
one() {
  local name=$1 body=$2 np=$3 cell=$4 steps=$5 L="$OUT/$2/labels"
  for side in old new; do
    local lib=$NEW_LIB; [ $side = old ] && lib=$OLD_LIB
    (
      d="$OUT/$side/$name"; mkdir -p "$d"
      s=$(date +%s.%N)
      LD_LIBRARY_PATH="$lib" timeout "$LIMIT" "$B/btr_scene_from_labels" "$L/prone_labels.nii.gz" --labels "$L/labels.yaml" $np \
        --cell-size "$cell" --prone-landmarks "$L/prone_landmarks.mrk.json" --supine-landmarks "$L/supine_landmarks.mrk.json" \
        --supine-surface "$L/supine_surface.obj" $(truth "$L") -o "$d/scene" > "$d/mesh.log" 2>&1
      rc=$?; e=$(date +%s.%N)
      if [ $rc -eq 124 ]; then echo "$name $side hung" > "$d/row"; exit; fi
      tets=$(grep -o "^\[labels\] [0-9]* tetrahedra" "$d/mesh.log" | grep -o "[0-9]*")
      ntum=$(grep -c ": centroid (" "$d/mesh.log")
      LD_LIBRARY_PATH="$lib" "$B/btr_register" "$d/scene/scene.yaml" -q ${steps:+-s $steps} --cell-size 0 -o "$d/reg" > "$d/reg.log" 2>&1
      errs=$(/usr/bin/python3 -c "
import json,sys
r=json.load(open('$d/reg/report.json'))
e=[t['centroid_distance_mm'] for t in r['tumours'] if t.get('centroid_distance_mm') is not None]
print('%.3f %.3f %s' % (min(e), max(e), r.get('converged')))" 2>/dev/null || echo "- - -")
      echo "$name $side mesh_s=$(echo "$e - $s" | bc) tets=$tets tumours=$ntum errors_min_max_converged=$errs" > "$d/row"
    ) &
  done
  wait
  cat "$OUT/old/$name/row" "$OUT/new/$name/row" | tee -a "$OUT/rows.txt"
}
rm -f "$OUT/rows.txt"
for c in 5 6 7 8; do one "p8_c$c" p8 --not-prone $c landmarks,surface; done
one mri_c7 mri --not-prone 7 ""
for c in 7 9; do one "het_c$c" het "" $c ""; done
