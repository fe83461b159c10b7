#!/usr/bin/env bash
# Mesh draws of the re-meshed scenes (S*, C*): fast now (nodal, 11 mm) at 10.89 / 11.11 mm, and
# fast until now (a copy of the scene with material.volume_form: element stated) at 8.91 / 9.09
# mm, 1 % either side of each size; with the nominal-size runs of run.sh (fastn11, fast), three
# meshes per point. One OpenMP thread per call, two calls side by side.
# Usage: bash draws.sh OUT NAME=SCENE.yaml ...   (the copies are written beside each scene)
set -uo pipefail
OUT=$1; shift
BIN=${BTR_BIN:-/work/main/build/ws/devel/lib/breast_tumour_registration}/btr_register
export OMP_NUM_THREADS=1
mkdir -p "$OUT"
copy_element() {
  local copy="$(dirname "$1")/.fast_element_$2.yaml"
  /usr/bin/python3 - "$1" "$copy" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1]))
s.setdefault('material', {})['volume_form'] = 'element'
yaml.safe_dump(s, open(sys.argv[2], 'w'))
PY
  echo "$copy"
}
jobs=()
for spec in "$@"; do
  name=${spec%%=*}; scene=${spec#*=}
  e=$(copy_element "$scene" "$name")
  for c in 10.89 11.11; do jobs+=("draw_fastn11_$c $name $scene --preset fast --cell-size $c"); done
  for c in 8.91 9.09; do jobs+=("draw_fast_$c $name $e --preset fast --cell-size $c"); done
done
run() { v=$1; n=$2; sc=$3; shift 3; "$BIN" "$sc" --out "$OUT/$v/$n" -q "$@" > "$OUT/${v}_$n.log" 2>&1; echo "exit $?" >> "$OUT/${v}_$n.log"; }
export -f run; export OUT BIN
printf '%s\n' "${jobs[@]}" | xargs -P 2 -L 1 bash -c 'run "$@"' _
