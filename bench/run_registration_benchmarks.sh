#!/usr/bin/env bash
# Reproduces the registration tables of BENCHMARKS.md: phantoms at ~5k, ~35k (the thesis's
# size) and ~100k tetrahedra (E = 3400 Pa), each registered with every preset, repeated;
# medians of the seconds and the worst tumour centroid error over the five tumours, read
# from report.json. Then the misalignment cases of thesis Sec. 5.2.5 on the ~35k phantom.
# Usage: bash bench/run_registration_benchmarks.sh [repeats]   (after scripts/setup.sh)
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$REPO_ROOT/build/ws/devel/lib/breast_tumour_registration"
REPEATS="${1:-5}"
WORK="${BTR_BENCH_DIR:-$(mktemp -d)}"
summarize() {  # report files... -> "median prepare | median registration | worst error | median error"
  /usr/bin/python3 - "$@" <<'PY'
import json, statistics, sys
reps = [json.load(open(p)) for p in sys.argv[1:]]
prep = statistics.median(r["seconds"]["prepare"] for r in reps)
reg = statistics.median(r["seconds"]["registration_total"] for r in reps)
steps = {}
for r in reps:
    for k, v in r["seconds"].items():
        if k in ("rigid", "landmark", "surface", "gravity"): steps.setdefault(k, []).append(v)
errs = [t["centroid_distance_mm"] for t in reps[0]["tumours"]]
split = ", ".join(f"{k} {statistics.median(v):.3f}" for k, v in steps.items())
print(f"{prep:.3f} | {reg:.3f} ({split}) | {prep + reg:.3f} | {max(errs):.3f} | {statistics.mean(errs):.3f}")
PY
}
echo "# $(date -u +%F) on $(nproc) cores; repeats=$REPEATS; work dir $WORK"
echo
echo "| cell [mm] | tets | preset | preparation [s] | registration [s] (per step) | end to end [s] | worst error [mm] | mean error [mm] |"
echo "|---|---|---|---|---|---|---|---|"
for h in 9 4.7 3.3; do
  "$BIN/btr_phantom" --out "$WORK/ph$h" --cell-size "$h" --quiet > /dev/null
  tets=$(grep -E "^  tetrahedra:" "$WORK/ph$h/scene.yaml" | awk '{print $2}')
  for p in fast balanced accurate; do
    reports=()
    for i in $(seq 1 "$REPEATS"); do
      "$BIN/btr_register" "$WORK/ph$h/scene.yaml" --out "$WORK/r_${h}_${p}_$i" --preset "$p" --quiet > /dev/null 2>&1 || true
      reports+=("$WORK/r_${h}_${p}_$i/report.json")
    done
    echo "| $h | $tets | $p | $(summarize "${reports[@]}") |"
  done
done
echo
echo "Misalignment (thesis Sec. 5.2.5) on the 4.7 mm phantom, preset balanced, with and without the rigid step:"
echo
echo "| misalignment | with rigid step: worst error [mm] | without: worst error [mm] |"
echo "|---|---|---|"
for mis in "rotation_deg: [15, 0, 0]" "rotation_deg: [0, 0, 15]" "translation_mm: [10, 0, 0]" "translation_mm: [0, 0, 10]" "translation_mm: [0, 0, -10]" "rotation_deg: [15, 15, 15], translation_mm: [10, 10, 10]"; do
  cp "$WORK/ph4.7/scene.yaml" "$WORK/ph4.7/mis.yaml"
  echo "misalignment: {$mis}" >> "$WORK/ph4.7/mis.yaml"
  "$BIN/btr_register" "$WORK/ph4.7/mis.yaml" --out "$WORK/mis_on" --quiet > /dev/null 2>&1 || true
  "$BIN/btr_register" "$WORK/ph4.7/mis.yaml" --out "$WORK/mis_off" --steps landmarks,surface --quiet > /dev/null 2>&1 || true
  on=$(summarize "$WORK/mis_on/report.json" | awk -F'|' '{print $4}')
  off=$(summarize "$WORK/mis_off/report.json" | awk -F'|' '{print $4}')
  echo "| $mis | $on | $off |"
done
