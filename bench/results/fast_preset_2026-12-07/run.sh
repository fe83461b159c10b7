#!/usr/bin/env bash
# Candidates for the fast preset: the scene with material.volume_form: nodal stated (a copy beside
# it), --preset fast at its 9 mm and at --cell-size 11; fast and balanced as they are again.
set -uo pipefail
OUT=$1; shift
BIN=${BTR_BIN:-/work/main/build/ws/devel/lib/breast_tumour_registration}/btr_register
export OMP_NUM_THREADS=1
mkdir -p "$OUT"
copy_nodal() {
  local copy="$(dirname "$1")/.fast_nodal_$2.yaml"
  /usr/bin/python3 - "$1" "$copy" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1]))
s.setdefault('material', {})['volume_form'] = 'nodal'
yaml.safe_dump(s, open(sys.argv[2], 'w'))
PY
  echo "$copy"
}
jobs=()
for spec in "$@"; do
  name=${spec%%=*}; scene=${spec#*=}
  c=$(copy_nodal "$scene" "$name")
  jobs+=("fast $name $scene --preset fast" "fastn9 $name $c --preset fast" "fastn11 $name $c --preset fast --cell-size 11" "bal $name $scene --preset balanced")
done
run() { v=$1; n=$2; sc=$3; shift 3; "$BIN" "$sc" --out "$OUT/$v/$n" -q "$@" > "$OUT/${v}_$n.log" 2>&1; echo "exit $?" >> "$OUT/${v}_$n.log"; }
export -f run; export OUT BIN
printf '%s\n' "${jobs[@]}" | xargs -P 2 -L 1 bash -c 'run "$@"' _
