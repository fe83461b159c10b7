#!/usr/bin/env bash
# Mesh draws (BENCHMARKS.md, "One mesh is one draw"): each re-meshed scene with the balanced
# preset at 8.91 and 9.09 mm, the new accurate at 6.93 and 7.07 mm, and the old accurate (nodal
# 5 mm, linear unload: the scene with material.unload_element_order: linear) at 4.95 and 5.05 mm.
set -uo pipefail
OUT=$1; shift
BIN=/work/main/build/ws/devel/lib/breast_tumour_registration/btr_register
export OMP_NUM_THREADS=1
mkdir -p "$OUT"
jobs=()
for spec in "$@"; do
  name=${spec%%=*}; scene=${spec#*=}
  l="$(dirname "$scene")/.acc_l_$name.yaml"
  /usr/bin/python3 - "$scene" "$l" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1]))
s.setdefault('material', {})['unload_element_order'] = 'linear'
yaml.safe_dump(s, open(sys.argv[2], 'w'))
PY
  for c in 8.91 9.09; do jobs+=("bal_$c $name $scene --preset balanced --cell-size $c"); done
  for c in 6.93 7.07; do jobs+=("acc_$c $name $scene --preset accurate --cell-size $c"); done
  for c in 4.95 5.05; do jobs+=("acc5_$c $name $l --preset accurate --cell-size $c"); done
done
run() { v=$1; n=$2; sc=$3; shift 3; "$BIN" "$sc" --out "$OUT/$v/$n" -q "$@" > "$OUT/${v}_$n.log" 2>&1; echo "exit $?" >> "$OUT/${v}_$n.log"; }
export -f run; export OUT BIN
printf '%s\n' "${jobs[@]}" | xargs -P 2 -L 1 bash -c 'run "$@"' _
