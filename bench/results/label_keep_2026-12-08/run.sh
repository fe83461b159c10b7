#!/usr/bin/env bash
# A label scene's own mesh against the engine's re-mesh of it, per preset. Each scene is
# registered twice with the same build: as the call did before this change (the engine re-meshed
# a tetrahedral scene whose mean edge read finer than the preset's cells: a label mesh's gland
# interface made it so) and with the scene's mesh kept (--cell-size 0, which is what a label
# scene that states its prone.cell_size_mm now gets wherever it is not clearly finer than the
# preset's size). Where the default kept the mesh anyway, the pair is one run.
# Scenes: SfePy's BR and AR bodies as label maps (bench/results/label_init_2026-12-07/run_sfepy.sh
# writes them: LSF/<body>_<E>/new/scene) and the phantoms' label scenes of the same study
# (LINIT/new/<name>/scene: run.sh).
# Usage: LSF=/tmp/lsf LINIT=/tmp/linit [BIN=<copy of devel/lib/breast_tumour_registration> LIB=<copy of
# devel/lib>] bash run.sh OUT (the copies of a build from 552c6ac give the calls as they were)
set -uo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
B="${BIN:-$REPO/build/ws/devel/lib/breast_tumour_registration}"
[ -n "${LIB:-}" ] && export LD_LIBRARY_PATH="$LIB"
LSF="${LSF:-/tmp/lsf}"; LINIT="${LINIT:-/tmp/linit}"; OUT="$1"
export OMP_NUM_THREADS=1
mkdir -p "$OUT"
summary() {  # report.json -> worst tumour, largest axis-ratio error, converged
  /usr/bin/python3 -c "
import json
r=json.load(open('$1'))
t=[x for x in r['tumours'] if x.get('centroid_distance_mm') is not None]
a=max(abs(x['axis_ratio']/x['truth_axis_ratio']-1)*100 for x in t)
print('worst=%.3f axis_pct=%.1f converged=%s' % (max(x['centroid_distance_mm'] for x in t), a, r.get('converged')))" 2>/dev/null || echo "worst=- axis_pct=- converged=-"
}
run() {  # run NAME SCENE PRESET STEPS SIDE [ARGS]
  local name=$1 scene=$2 preset=$3 steps=$4 side=$5; shift 5
  local d="$OUT/$name/$preset/$side"; mkdir -p "$d"
  local s=$(date +%s.%N)
  "$B/btr_register" "$scene" -q -p "$preset" ${steps:+-s $steps} "$@" -o "$d/reg" > "$d/reg.log" 2>&1
  local rc=$? e=$(date +%s.%N)
  local meshed=kept; grep -q "re-tetrahedralized the prone model" "$d/reg.log" && meshed=remeshed
  echo "$name $preset $side rc=$rc $meshed tets=$(/usr/bin/python3 -c "import json;print(json.load(open('$d/reg/report.json'))['mesh']['tetrahedra'])" 2>/dev/null) $(summary "$d/reg/report.json") s=$(printf %.1f $(echo "$e - $s" | bc))"
}
rm -f "$OUT/rows.txt"
scenes=()
for n in BR_1000 BR_3400 AR_1000 AR_3400; do scenes+=("$n|$LSF/$n/new/scene/scene.yaml|"); done
for n in het_c7 het_c9; do scenes+=("$n|$LINIT/new/$n/scene/scene.yaml|"); done
for n in p8_c6 p8_c8; do scenes+=("$n|$LINIT/new/$n/scene/scene.yaml|landmarks,surface"); done
for preset in balanced fast accurate; do
  for entry in "${scenes[@]}"; do
    IFS='|' read -r name scene steps <<< "$entry"
    row=$(run "$name" "$scene" "$preset" "$steps" default)
    echo "$row" | tee -a "$OUT/rows.txt"
    if [[ $row == *remeshed* ]]; then run "$name" "$scene" "$preset" "$steps" keep --cell-size 0 | tee -a "$OUT/rows.txt"; fi
  done
done
