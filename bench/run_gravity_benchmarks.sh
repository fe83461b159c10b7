#!/usr/bin/env bash
# Reproduces the gravity-solve table of BENCHMARKS.md: the phantom's prone configuration at
# ~5k, ~35k and ~100k tetrahedra (cell sizes 9, 4.7, 3.3 mm), medians over repeats, peak
# memory from /usr/bin/time -v, and the same solves without lagged-factor reuse.
# Usage: bash bench/run_gravity_benchmarks.sh [repeats]   (after scripts/setup.sh)
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$REPO_ROOT/build/ws/devel/lib/breast_tumour_registration/btr_bench_gravity"
REPEATS="${1:-5}"
echo "# $(date -u +%F) on $(nproc) cores; repeats=$REPEATS"
header=--header
for mode in "" "--no-reuse"; do
  echo
  echo "mode: ${mode:-lagged-factor PCG (default)}"
  for h in 9 4.7 3.3; do
    out=$(/usr/bin/time -v "$BIN" --cell-size "$h" --repeats "$REPEATS" $header $mode 2>/tmp/btr_time.txt)
    mem=$(awk -F: '/Maximum resident set size/ {gsub(/ /,"",$2); printf "%.0f", $2/1024}' /tmp/btr_time.txt)
    echo "$out" | sed "\$s/\$/ peak ${mem} MiB |/"
    header=""
  done
  header=--header
done
