#!/usr/bin/env bash
# Every scene with `--preset accurate` (after the preset's change): two calls at a time.
set -uo pipefail
OUT=$1; shift
BIN=/work/main/build/ws/devel/lib/breast_tumour_registration/btr_register
export OMP_NUM_THREADS=1
mkdir -p "$OUT"
run() { n=${1%%=*}; sc=${1#*=}; "$BIN" "$sc" --out "$OUT/accnew/$n" -q --preset accurate > "$OUT/accnew_$n.log" 2>&1; echo "exit $?" >> "$OUT/accnew_$n.log"; }
export -f run; export OUT BIN
printf '%s\n' "$@" | xargs -P 2 -L 1 bash -c 'run "$@"' _
