#!/usr/bin/env bash
# The accurate preset's study (README.md here). One OpenMP thread per call, two calls at a time.
#   candidates: each scene with balanced, with accurate as it was, and with the unload's quadratic
#               elements stated in a copy of the scene at --preset accurate --cell-size 9 and 7
#               (run on 7c78f03's build, before the preset changed);
#   preset:     each scene with --preset accurate (after the change);
#   draws:      each scene on two more meshes (1 % either side of each point's size): balanced at
#               8.91 / 9.09 mm, accurate at 6.93 / 7.07 mm, accurate as it was (the linear unload
#               stated) at 4.95 / 5.05 mm.
# The scene copies are written beside each scene (their relative paths stay valid).
# Usage: bash run.sh candidates|preset|draws OUT NAME=SCENE.yaml ...
set -uo pipefail
MODE=$1; OUT=$2; shift 2
BIN=${BTR_BIN:-/work/main/build/ws/devel/lib/breast_tumour_registration}/btr_register
export OMP_NUM_THREADS=1
mkdir -p "$OUT"
copy_with() {  # SCENE NAME ORDER: a copy of SCENE with material.unload_element_order: ORDER
  local copy
  copy="$(dirname "$1")/.acc_${3}_$2.yaml"
  /usr/bin/python3 - "$1" "$copy" "$3" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1]))
s.setdefault('material', {})['unload_element_order'] = sys.argv[3]
yaml.safe_dump(s, open(sys.argv[2], 'w'))
PY
  echo "$copy"
}
jobs=()
for spec in "$@"; do
  name=${spec%%=*}; scene=${spec#*=}
  case "$MODE" in
    candidates)
      q=$(copy_with "$scene" "$name" quadratic)
      jobs+=("bal $name $scene --preset balanced" "acc5 $name $scene --preset accurate"
             "acc9q $name $q --preset accurate --cell-size 9" "acc7q $name $q --preset accurate --cell-size 7") ;;
    preset) jobs+=("accnew $name $scene --preset accurate") ;;
    draws)
      l=$(copy_with "$scene" "$name" linear)
      for c in 8.91 9.09; do jobs+=("bal_$c $name $scene --preset balanced --cell-size $c"); done
      for c in 6.93 7.07; do jobs+=("acc_$c $name $scene --preset accurate --cell-size $c"); done
      for c in 4.95 5.05; do jobs+=("acc5_$c $name $l --preset accurate --cell-size $c"); done ;;
    *) echo "mode: candidates, preset or draws" >&2; exit 2 ;;
  esac
done
run() { v=$1; n=$2; sc=$3; shift 3; "$BIN" "$sc" --out "$OUT/$v/$n" -q "$@" > "$OUT/${v}_$n.log" 2>&1; echo "exit $?" >> "$OUT/${v}_$n.log"; }
export -f run; export OUT BIN
printf '%s\n' "${jobs[@]}" | xargs -P 2 -L 1 bash -c 'run "$@"' _
