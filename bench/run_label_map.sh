#!/usr/bin/env bash
# Issue 15's figure: time and memory from a 512 x 512 x 160 label map (0.7 x 0.7 x 1.0 mm, an
# axial breast MRI's field of view) to a registered tumour. The body is the 6 mm phantom as a
# segmented image (btr_phantom --label-map); then, REPEATS times each, timed with /usr/bin/time:
#   1. btr_scene_from_labels: read the NIfTI, mesh it (CGAL Mesh_3, 7 mm), write the scene;
#   2. btr_register: the default plan (steps auto, balanced) on that scene.
# Prints one line per run (wall s, peak RSS MB) and the medians. Usage:
#   bash bench/run_label_map.sh [OUT_DIR] [REPEATS]
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$REPO_ROOT/build/ws/devel/lib/breast_tumour_registration"
OUT="${1:-$REPO_ROOT/out/bench_label_map}"
REPEATS="${2:-3}"
mkdir -p "$OUT"
"$BIN/btr_phantom" -q --out "$OUT/phantom" --cell-size 6 --label-map "$OUT/labels" --voxel-size 0.7,0.7,1.0 \
  --label-map-voxels 512,512,160 | grep "label map"
L="$OUT/labels"
truth=()
for t in top middle bottom left right; do truth+=(--truth "$t,$L/tumour_${t}_prone.obj,$L/tumour_${t}_supine.obj"); done
printf "stiffness: {gland: 1, tumour: 1}\n" > "$L/labels.yaml"
run() {  # name, command...: appends "name wall_s rss_mb"
  local name=$1; shift
  /usr/bin/time -f "%e %M" -o "$OUT/time.txt" "$@" > "$OUT/$name.log" 2>&1 || { echo "$name failed (see $OUT/$name.log)"; exit 1; }
  read -r wall kb < "$OUT/time.txt"
  echo "$name $wall $((kb / 1024))" | tee -a "$OUT/runs.txt"
}
rm -f "$OUT/runs.txt"
for r in $(seq 1 "$REPEATS"); do
  run mesh "$BIN/btr_scene_from_labels" "$L/prone_labels.nii.gz" --labels "$L/labels.yaml" --not-prone \
    --prone-landmarks "$L/prone_landmarks.mrk.json" --supine-landmarks "$L/supine_landmarks.mrk.json" \
    --supine-surface "$L/supine_surface.obj" "${truth[@]}" --out "$OUT/scene"
  run register "$BIN/btr_register" "$OUT/scene/scene.yaml" --out "$OUT/registration" --quiet
done
grep -E "tetrahedra" "$OUT/mesh.log"
grep -E "centroid error" "$OUT/register.log" | sed 's/, volume ratio.*centroid error/: centroid error/'
median() { sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
for name in mesh register; do
  wall=$(awk -v n="$name" '$1 == n { print $2 }' "$OUT/runs.txt" | median)
  rss=$(awk -v n="$name" '$1 == n { print $3 }' "$OUT/runs.txt" | median)
  echo "median $name: $wall s, $rss MB peak ($REPEATS runs)"
done
