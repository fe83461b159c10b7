#!/bin/bash
# The presets' speed/accuracy front with the volume form as a knob (issues 10 and 13): for each
# scene, btr_bench_tradeoff sweeps the presets' tolerances over the simulation mesh sizes, once
# with the element volume form and once with the nodal one (the scene copied with
# material.volume_form set), and writes OUT/<name>_<form>.csv. The scenes should have truth the
# method's solver did not make (bench/make_independent_truth.py, btr_phantom --element-order
# quadratic). One OpenMP thread per process; JOBS processes side by side. The scene copies are
# written beside the scenes (their relative paths stay valid) and removed at the end.
# Summary: python3 bench/summarize_preset_front.py OUT
# MESH_DRAWS=N: each point with a cell size on N meshes within 1 % of it (medians and the range;
# a mesh is one draw: BENCHMARKS.md, "One mesh is one draw").
# Usage: [JOBS=2] [REPEATS=3] [CELLS="5 7 9"] [FORMS="element nodal"] [MESH_DRAWS=1] [PRESETS="fast balanced accurate"] [KNOBS="preset cell_size_mm"] bash bench/run_preset_front.sh OUT name=scene.yaml ...
set -euo pipefail
OUT=${1:?usage: run_preset_front.sh OUT name=scene.yaml ...}
shift
JOBS=${JOBS:-2}
REPEATS=${REPEATS:-3}
CELLS=${CELLS:-5 7 9}
FORMS=${FORMS:-element nodal}
MESH_DRAWS=${MESH_DRAWS:-1}
PRESETS=${PRESETS:-fast balanced accurate}
KNOBS=${KNOBS:-preset cell_size_mm}
here=$(cd "$(dirname "$0")" && pwd)
bin="$here/../build/ws/devel/lib/breast_tumour_registration"
mkdir -p "$OUT"
jobs_list=()
copies=()
trap 'rm -f "${copies[@]}"' EXIT
for arg in "$@"; do
  name=${arg%%=*}; scene=${arg#*=}
  dir=$(cd "$(dirname "$scene")" && pwd)
  for form in $FORMS; do
    copy="$dir/.front_${name}_${form}.yaml"  # beside the scene: its relative paths stay valid
    /usr/bin/python3 - "$scene" "$copy" "$form" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1]))
s.setdefault('material', {})['volume_form'] = sys.argv[3]
s['material']['nodal_fallback'] = True
yaml.safe_dump(s, open(sys.argv[2], 'w'))
PY
    jobs_list+=("$name $form $copy")
    copies+=("$copy")
  done
done
run() {  # name form scene
  OMP_NUM_THREADS=1 "$bin/btr_bench_tradeoff" "$3" --repeats "$REPEATS" --knobs $KNOBS \
    --cell-sizes $CELLS --mesh-draws "$MESH_DRAWS" --base-presets $PRESETS -o "$OUT/$1_$2.csv" > "$OUT/$1_$2.log" 2>&1 || echo "$1 $2: exit $?" >> "$OUT/failures.txt"
}
export -f run
export OUT REPEATS CELLS MESH_DRAWS PRESETS KNOBS bin
printf '%s\n' "${jobs_list[@]}" | xargs -P "$JOBS" -L 1 bash -c 'run "$0" "$1" "$2"'
echo "wrote $OUT/*.csv"
