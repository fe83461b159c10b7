#!/usr/bin/env bash
# SfePy's bodies (truth our solver did not make) as label maps, old and new label mesher side by
# side, against the same body's surface scene. The label map comes from
# bench/probes/label_map_from_surface_scene.cpp (the prone surface meshed at 3 mm to carry the
# landmarks and a gland label by tetrahedron centroid; tumours by their prone surfaces; 1 mm
# voxels; a 5 mm muscle slab behind the chest wall). btr_scene_from_labels: gland 3x, tumours 8x
# (the generator's ratios), prone (unloaded), the balanced preset's size; E estimated
# (`youngs_modulus: estimate` written into the scene, as the surface scene has it). Bodies: FRONT
# as bench/results/tumour_cells_2026-12-07/README.md makes them (BR, AR).
# Usage: OLD_LIB=/tmp/oldlab FRONT=/tmp/front bash run_sfepy.sh OUT
set -uo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
NEW_LIB="$REPO/build/ws/devel/lib"; OLD_LIB="${OLD_LIB:?a copy of devel/lib built from 51cdc3a}"
F="${FRONT:-/tmp/front}"; OUT="$1"; LIMIT="${LIMIT:-120}"
B="$NEW_LIB/breast_tumour_registration"
export OMP_NUM_THREADS=1
mkdir -p "$OUT"
g++ -std=gnu++17 -O2 -DNDEBUG -I"$REPO/include" -I/usr/include/eigen3 -I/usr/include/suitesparse \
  "$REPO/bench/probes/label_map_from_surface_scene.cpp" -o "$OUT/lmss" -L"$NEW_LIB" -lbtr_simulation -lbtr_registration \
  -lbtr_io -lbtr_geometry -lbtr_fem -lbtr_base -lcholmod -Wl,-rpath,"$NEW_LIB"
printf "fat: [1]\ngland: [2]\ntumour: [3]\nmuscle: 4\nstiffness: {gland: 3, tumour: 8}\n" > "$OUT/labels.yaml"
errors() {  # report.json -> "min max converged"
  /usr/bin/python3 -c "
import json
r=json.load(open('$1'))
e=[t['centroid_distance_mm'] for t in r['tumours'] if t.get('centroid_distance_mm') is not None]
print('%.3f %.3f %s' % (min(e), max(e), r.get('converged')))" 2>/dev/null || echo "- - -"
}
rm -f "$OUT/rows.txt"
for body in BR AR; do
  for E in 1000 3400; do
    name="${body}_$E"; S="$F/$body/E$E/scene_estimated_regions.yaml"; L="$OUT/$name/labels"
    [ -f "$S" ] || continue
    "$OUT/lmss" "$S" "$L" 3 1 > "$OUT/$name.map.log" 2>&1 || { echo "$name map failed"; continue; }
    truth=(); for t in $(ls "$L" | sed -n 's/^tumour_\(.*\)_prone.obj$/\1/p'); do truth+=(--truth "$t,$L/tumour_${t}_prone.obj,$L/tumour_${t}_supine.obj"); done
    for side in old new surface; do
      (
        d="$OUT/$name/$side"; mkdir -p "$d"; lib=$NEW_LIB; [ $side = old ] && lib=$OLD_LIB
        if [ $side = surface ]; then
          LD_LIBRARY_PATH="$lib" "$B/btr_register" "$S" -q -o "$d/reg" > "$d/reg.log" 2>&1
          echo "$name $side rc=$? errors_min_max_converged=$(errors "$d/reg/report.json")" > "$d/row"; exit
        fi
        LD_LIBRARY_PATH="$lib" timeout "$LIMIT" "$B/btr_scene_from_labels" "$L/prone_labels.nii.gz" --labels "$OUT/labels.yaml" \
          --prone-landmarks "$L/prone_landmarks.mrk.json" --supine-landmarks "$L/supine_landmarks.mrk.json" \
          --supine-surface "$L/supine_surface.obj" "${truth[@]}" -o "$d/scene" > "$d/mesh.log" 2>&1
        rc=$?; [ $rc -eq 124 ] && { echo "$name $side hung" > "$d/row"; exit; }
        [ $rc -ne 0 ] && { echo "$name $side mesh_rc=$rc" > "$d/row"; exit; }
        sed -i 's/^  youngs_modulus: [0-9.]*$/  youngs_modulus: estimate/' "$d/scene/scene.yaml"
        tets=$(grep -o "^\[labels\] [0-9]* tetrahedra" "$d/mesh.log" | grep -o "[0-9]*")
        LD_LIBRARY_PATH="$lib" "$B/btr_register" "$d/scene/scene.yaml" -q -o "$d/reg" > "$d/reg.log" 2>&1
        echo "$name $side tets=$tets rc=$? errors_min_max_converged=$(errors "$d/reg/report.json")" > "$d/row"
      ) &
      [ $side = new ] && wait
    done
    wait
    cat "$OUT/$name"/{old,new,surface}/row | tee -a "$OUT/rows.txt"
  done
done
