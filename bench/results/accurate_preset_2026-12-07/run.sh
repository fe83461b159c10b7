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
source "$(dirname "$0")/../../preset_runs.sh"
MODE=$1; OUT=$2; shift 2
jobs=()
for spec in "$@"; do
  name=${spec%%=*}; scene=${spec#*=}
  case "$MODE" in
    candidates)
      q=$(scene_copy "$scene" "acc_quadratic_$name" unload_element_order quadratic)
      jobs+=("bal $name $scene --preset balanced" "acc5 $name $scene --preset accurate"
             "acc9q $name $q --preset accurate --cell-size 9" "acc7q $name $q --preset accurate --cell-size 7") ;;
    preset) jobs+=("accnew $name $scene --preset accurate") ;;
    draws)
      l=$(scene_copy "$scene" "acc_linear_$name" unload_element_order linear)
      for c in 8.91 9.09; do jobs+=("bal_$c $name $scene --preset balanced --cell-size $c"); done
      for c in 6.93 7.07; do jobs+=("acc_$c $name $scene --preset accurate --cell-size $c"); done
      for c in 4.95 5.05; do jobs+=("acc5_$c $name $l --preset accurate --cell-size $c"); done ;;
    *) echo "mode: candidates, preset or draws" >&2; exit 2 ;;
  esac
done
run_jobs "$OUT" "${jobs[@]}"
