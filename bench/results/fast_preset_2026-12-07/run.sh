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
MODE=$1; OUT=$2; shift 2
jobs=()
for spec in "$@"; do
  name=${spec%%=*}; scene=${spec#*=}
  case "$MODE" in
    candidates)
      c=$(scene_copy "$scene" "fast_nodal_$name" volume_form nodal)
      jobs+=("fast $name $scene --preset fast" "fastn9 $name $c --preset fast"
             "fastn11 $name $c --preset fast --cell-size 11" "bal $name $scene --preset balanced") ;;
    draws)
      e=$(scene_copy "$scene" "fast_element_$name" volume_form element)
      for c in 10.89 11.11; do jobs+=("draw_fastn11_$c $name $scene --preset fast --cell-size $c"); done
      for c in 8.91 9.09; do jobs+=("draw_fast_$c $name $e --preset fast --cell-size $c"); done ;;
    *) echo "mode: candidates or draws" >&2; exit 2 ;;
  esac
done
run_jobs "$OUT" "${jobs[@]}"
