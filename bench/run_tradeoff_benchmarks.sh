#!/usr/bin/env bash
# Reproduces the speed/accuracy section of BENCHMARKS.md: a ground-truth phantom at the
# thesis's size (cell 4.7 mm, ~35k tetrahedra, E = 3400 Pa), the sweep of btr_bench_tradeoff
# (simulation mesh, subspace size, landmark tolerance, projection budget, presets; median of
# the repeats), the Pareto plot, and a profile of every preset with btr_register.
# Usage: bash bench/run_tradeoff_benchmarks.sh [repeats]   (after scripts/setup.sh)
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$REPO_ROOT/build/ws/devel/lib/breast_tumour_registration"
REPEATS="${1:-3}"
WORK="${BTR_BENCH_DIR:-$(mktemp -d)}"
OUT="$REPO_ROOT/bench/results"
mkdir -p "$OUT"
echo "# $(date -u +%F) on $(nproc) cores; repeats=$REPEATS; work dir $WORK"
"$BIN/btr_phantom" --out "$WORK/gt" --cell-size 4.7 --quiet | tail -1
"$BIN/btr_bench_tradeoff" "$WORK/gt/scene.yaml" --repeats "$REPEATS" --out "$OUT/tradeoff.csv"
/usr/bin/python3 "$REPO_ROOT/bench/plot_tradeoff.py" "$OUT/tradeoff.csv" --out "$OUT/tradeoff.png"
echo
echo "Profile of each preset (btr_register, one run each):"
for p in fast balanced accurate; do
  echo "## $p"
  "$BIN/btr_register" "$WORK/gt/scene.yaml" --preset "$p" --out "$WORK/profile_$p" --quiet | grep -v "^\[tumour" || true
done
