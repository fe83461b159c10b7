#!/usr/bin/env bash
# The surface step's convergence (issue 10, 2026-12-02): what "converged" bounds, Anderson
# acceleration, and the not-converged rate of the quick experiment suite on two bodies.
#  1. btr_bench_tradeoff's anderson_depth and projection_tolerance knobs (balanced, median of 3)
#     on the phantom at 6 mm and 1000 Pa told its E and prone gravity (unload planned), and on
#     SfePy's 1000 Pa-fat truth (the full method: unloaded, regions, E estimated, nodal volume);
#  2. the quick suite at E = 400, 1000, 3400, 12000 Pa on the phantom (8 mm) and on the TetGen
#     body of bench/make_shape_model.py, summarized by bench/summarize_convergence.py.
# Usage: bash bench/run_convergence.sh [out_dir]   (after scripts/setup.sh)
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$REPO/build/ws/devel/lib/breast_tumour_registration"
OUT="${1:-$REPO/out/convergence}"
mkdir -p "$OUT"
[ -f "$OUT/ph1000/scene.yaml" ] || "$BIN/btr_phantom" -q --out "$OUT/ph1000" -E 1000 --cell-size 6 > "$OUT/ph1000.log"
sed 's/youngs_modulus: 3400/youngs_modulus: 1000/' "$OUT/ph1000/scene.yaml" > "$OUT/ph1000/scene_told_unload.yaml"
echo "prone_gravity: [0, 0, 9.81]" >> "$OUT/ph1000/scene_told_unload.yaml"
for s in "$OUT/ph1000/scene_told_unload.yaml" "$REPO/test/data/independent_truth_E1000/scene_estimated_regions_nodal.yaml"; do
  "$BIN/btr_bench_tradeoff" "$s" --repeats 3 --knobs anderson_depth projection_tolerance --out "$OUT/$(basename "$(dirname "$s")")_$(basename "$s" .yaml).csv"
done
[ -f "$OUT/shape/model.yaml" ] || /usr/bin/python3 "$REPO/bench/make_shape_model.py" "$OUT/shape"
"$BIN/btr_experiments" -q --quick --cell-size 8 -E 400 1000 3400 12000 --out "$OUT/suite_phantom"
"$BIN/btr_experiments" -q --quick --model "$OUT/shape/model.yaml" -E 400 1000 3400 12000 --out "$OUT/suite_shape"
/usr/bin/python3 "$REPO/bench/summarize_convergence.py" phantom="$OUT/suite_phantom/results.csv" shape="$OUT/suite_shape/results.csv"
