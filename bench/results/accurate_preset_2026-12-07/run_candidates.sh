#!/usr/bin/env bash
# The accurate preset's candidates on the 15 scenes (issue 10's front): each scene registered with
# `--preset accurate` as it is (linear unload, nodal 5 mm), and with the unload's quadratic elements
# stated in a copy of the scene at --cell-size 9 and 7 (the accurate tolerances on the balanced
# preset's model, and one size finer). Two calls at a time, one OpenMP thread each.
# Usage: bash run.sh OUT NAME=SCENE ...
set -uo pipefail
OUT=$1; shift
BIN=/work/main/build/ws/devel/lib/breast_tumour_registration/btr_register
export OMP_NUM_THREADS=1
mkdir -p "$OUT"
jobs=()
for spec in "$@"; do
  name=${spec%%=*}; scene=${spec#*=}
  q="$(dirname "$scene")/.acc_q_$name.yaml"
  /usr/bin/python3 - "$scene" "$q" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1]))
s.setdefault('material', {})['unload_element_order'] = 'quadratic'
yaml.safe_dump(s, open(sys.argv[2], 'w'))
PY
  jobs+=("bal $name $scene --preset balanced")
  jobs+=("acc5 $name $scene --preset accurate")
  jobs+=("acc9q $name $q --preset accurate --cell-size 9")
  jobs+=("acc7q $name $q --preset accurate --cell-size 7")
done
run() { v=$1; n=$2; sc=$3; shift 3; "$BIN" "$sc" --out "$OUT/$v/$n" -q "$@" > "$OUT/${v}_$n.log" 2>&1; echo "exit $?" >> "$OUT/${v}_$n.log"; }
export -f run; export OUT BIN
printf '%s\n' "${jobs[@]}" | xargs -P 2 -L 1 bash -c 'run "$@"' _
