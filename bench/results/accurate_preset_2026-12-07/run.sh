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
jobs_for() {  # MODE NAME SCENE
  local q l c
  case "$1" in
    candidates)
      q=$(scene_copy "$3" "acc_quadratic_$2" unload_element_order quadratic)
      jobs+=("bal $2 $3 --preset balanced" "acc5 $2 $3 --preset accurate"
             "acc9q $2 $q --preset accurate --cell-size 9" "acc7q $2 $q --preset accurate --cell-size 7") ;;
    preset) jobs+=("accnew $2 $3 --preset accurate") ;;
    draws)
      l=$(scene_copy "$3" "acc_linear_$2" unload_element_order linear)
      for c in 8.91 9.09; do jobs+=("bal_$c $2 $3 --preset balanced --cell-size $c"); done
      for c in 6.93 7.07; do jobs+=("acc_$c $2 $3 --preset accurate --cell-size $c"); done
      for c in 4.95 5.05; do jobs+=("acc5_$c $2 $l --preset accurate --cell-size $c"); done ;;
    *) echo "mode: candidates, preset or draws" >&2; return 1 ;;
  esac
}
study_main "$@"
