#!/usr/bin/env bash
# The fast preset's study (README.md here). One OpenMP thread per call, two calls at a time.
#   candidates: each scene with fast as it was (run before the change), with a copy stating
#               material.volume_form: nodal at --preset fast (9 mm) and --cell-size 11, and with
#               balanced;
#   draws:      the re-meshed scenes on two more meshes, 1 % either side of each size: fast now
#               (nodal) at 10.89 / 11.11 mm, fast as it was (a copy stating the element form) at
#               8.91 / 9.09 mm.
# Usage: bash run.sh candidates|draws OUT NAME=SCENE.yaml ...
set -uo pipefail
source "$(dirname "$0")/../../preset_runs.sh"
jobs_for() {  # MODE NAME SCENE
  local c e
  case "$1" in
    candidates)
      c=$(scene_copy "$3" "fast_nodal_$2" volume_form nodal)
      jobs+=("fast $2 $3 --preset fast" "fastn9 $2 $c --preset fast"
             "fastn11 $2 $c --preset fast --cell-size 11" "bal $2 $3 --preset balanced") ;;
    draws)
      e=$(scene_copy "$3" "fast_element_$2" volume_form element)
      for c in 10.89 11.11; do jobs+=("draw_fastn11_$c $2 $3 --preset fast --cell-size $c"); done
      for c in 8.91 9.09; do jobs+=("draw_fast_$c $2 $e --preset fast --cell-size $c"); done ;;
    *) echo "mode: candidates or draws" >&2; return 1 ;;
  esac
}
study_main "$@"
