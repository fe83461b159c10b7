#!/bin/bash
# Issue 14's calibration study (calibration_study.h): is the tumour's 95 % region right as often
# as it claims, on truth whose stiffness the method does not know?
#  1. Phantoms whose Young's modulus and Poisson's ratio are drawn over the default sources'
#     ranges (a Latin hypercube: E log-uniform over 200 to 3000 Pa, nu uniform over 0.45 to
#     0.499), each scene keeping the method's nominal 3400 Pa and 0.49.
#  2. The committed truth from an independent FEM code (SfePy, P2, heterogeneous fat / gland /
#     tumour, fat E 1000 and 3400 Pa), with the prone shape as rest and unloaded with regions.
# Every scene is registered in BTR_CAL_DRAWS noisy copies (landmarks 1.5 mm, depth 1 mm, gravity
# 2 deg: the sources' own draws), each with BTR_CAL_SAMPLES sampled re-registrations (0: the
# linearised region alone).
# BTR_CAL_STIFFNESS=estimate: the method estimates E from the (noisy) landmarks instead
# (`youngs_modulus: estimate` with the prone gravity, so the model is unloaded at the estimate):
# each phantom gets a scene_estimated.yaml beside its scene.yaml, and the independent truth runs
# its committed scene_estimated_regions.yaml. Every sample then estimates E again.
# BTR_CAL_TRUTH_ELEMENTS=quadratic: the phantoms' truth is made with 10-node tetrahedra
# (btr_phantom --element-order quadratic), a truth the method's own linear elements did not make;
# on the 8 mm mesh it folds below about 600 Pa. BTR_CAL_E_MIN: skip the phantoms softer than this.
# Usage: bash bench/run_calibration.sh OUT [phantom|independent|all]   (BTR_CAL_* below: sizes)
# Then:  /usr/bin/python3 scripts/plot_calibration.py OUT/*/calibration.csv --out OUT
set -euo pipefail
OUT=${1:?usage: run_calibration.sh OUT [phantom|independent|all]}
WHAT=${2:-all}
BODIES=${BTR_CAL_BODIES:-8} DRAWS=${BTR_CAL_DRAWS:-3} SAMPLES=${BTR_CAL_SAMPLES:-32} CELL=${BTR_CAL_CELL:-8}
PRESET=${BTR_CAL_PRESET:-balanced}
STIFFNESS=${BTR_CAL_STIFFNESS:-nominal}
case "$STIFFNESS" in nominal|estimate) ;; *) echo "BTR_CAL_STIFFNESS: nominal or estimate, got '$STIFFNESS'" >&2; exit 2 ;; esac
TRUTH_ELEMENTS=${BTR_CAL_TRUTH_ELEMENTS:-linear} E_MIN=${BTR_CAL_E_MIN:-0}
case "$TRUTH_ELEMENTS" in linear|quadratic) ;; *) echo "BTR_CAL_TRUTH_ELEMENTS: linear or quadratic, got '$TRUTH_ELEMENTS'" >&2; exit 2 ;; esac
here=$(cd "$(dirname "$0")" && pwd)
BIN=${BTR_BIN:-"$here/../build/ws/devel/lib/breast_tumour_registration"}  # BTR_BIN: another build
mkdir -p "$OUT/phantoms"
if [ "$WHAT" = phantom ] || [ "$WHAT" = all ]; then
  scenes=()
  # Stratified E (log scale) paired with a shuffled stratified nu: a Latin hypercube, seeded.
  while read -r E NU; do
    [ "$E" -ge "$E_MIN" ] || continue
    d="$OUT/phantoms/E${E}_nu${NU}"
    [ -f "$d/scene.yaml" ] || "$BIN/btr_phantom" -o "$d" -E "$E" --poisson-ratio "$NU" --cell-size "$CELL" \
        --element-order "$TRUTH_ELEMENTS" -q > "$d.log" 2>&1 \
      || { echo "phantom E=$E nu=$NU failed (see $d.log)"; continue; }
    if [ "$STIFFNESS" = estimate ]; then
      # The phantom's frame: prone gravity +z (btr_phantom's scene says so in its `frame`).
      sed -e '/^material:/,/^[a-z]/ s/^  youngs_modulus: 3400$/  youngs_modulus: estimate/' "$d/scene.yaml" > "$d/scene_estimated.yaml"
      grep -q '^  youngs_modulus: estimate$' "$d/scene_estimated.yaml" || { echo "$d/scene.yaml: no 'youngs_modulus: 3400' to replace" >&2; exit 1; }
      echo "prone_gravity: [0, 0, 9.81]" >> "$d/scene_estimated.yaml"
      scenes+=("$d/scene_estimated.yaml")
    else
      scenes+=("$d/scene.yaml")
    fi
  done < <(/usr/bin/python3 - "$BODIES" <<'PY'
import random, sys
n = int(sys.argv[1])
perm = list(range(n)); random.Random(14).shuffle(perm)
for i in range(n):
    e = 200 * 15 ** ((i + 0.5) / n)
    nu = 0.45 + 0.049 * (perm[i] + 0.5) / n
    print(round(e), round(nu, 4))
PY
)
  "$BIN/btr_calibration" "${scenes[@]}" --draws "$DRAWS" --samples "$SAMPLES" -p "$PRESET" -o "$OUT/phantom" \
    | tee "$OUT/phantom.log"
fi
if [ "$WHAT" = independent ] || [ "$WHAT" = all ]; then
  # One process per fat modulus (the two cores), each with the prone-as-rest and the unloaded
  # scene; then one CSV. One OpenMP thread each: two processes of two threads on two cores wait
  # at every parallel loop's barrier for a thread the other process holds (a stiffness search:
  # 28 s each side by side with the default threads, 12 s with one; BENCHMARKS.md).
  data="$here/../test/data"
  for E in ${BTR_CAL_FAT:-1000 3400}; do
    t="$data/independent_truth_E$E"
    if [ "$STIFFNESS" = estimate ]; then sc=("$t/scene_estimated_regions.yaml"); else sc=("$t/scene_prone.yaml" "$t/scene_unloaded_regions.yaml"); fi
    OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} "$BIN/btr_calibration" "${sc[@]}" \
      --draws "$DRAWS" --samples "$SAMPLES" -p "$PRESET" -o "$OUT/independent_E$E" > "$OUT/independent_E$E.log" 2>&1 &
  done
  wait
  mkdir -p "$OUT/independent"
  first=1
  for E in ${BTR_CAL_FAT:-1000 3400}; do
    if [ $first = 1 ]; then cat "$OUT/independent_E$E/calibration.csv"; first=0; else tail -n +2 "$OUT/independent_E$E/calibration.csv"; fi
  done > "$OUT/independent/calibration.csv"
  cat "$OUT"/independent_E*.log
fi
