#!/usr/bin/env bash
# Reproduces the experiment section of README.md / BENCHMARKS.md: every experiment of the
# thesis's Table 5.1 over its full sweeps and the 16 generating Young's moduli, on the
# built-in phantom (cell size in mm, default 8: ~7k tetrahedra), then the plots and the
# table of the thesis's ranges beside ours (summary.md).
# Usage: bash bench/run_experiments.sh [cell_size_mm] [extra btr_experiments options...]
#   e.g. bash bench/run_experiments.sh 8 --model my_model/model.yaml   (a user's rest model)
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$REPO_ROOT/build/ws/devel/lib/breast_tumour_registration"
CELL="${1:-8}"
shift || true
OUT="${BTR_EXPERIMENTS_DIR:-$REPO_ROOT/bench/results/experiments}"
mkdir -p "$OUT"
/usr/bin/time -v "$BIN/btr_experiments" --out "$OUT" --cell-size "$CELL" --quiet "$@" 2> "$OUT/time.txt"
grep -E "Elapsed|Maximum resident" "$OUT/time.txt"
/usr/bin/python3 "$REPO_ROOT/scripts/plot_experiments.py" "$OUT/results.csv" --out "$OUT"
