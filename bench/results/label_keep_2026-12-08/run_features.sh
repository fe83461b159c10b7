#!/usr/bin/env bash
# A re-mesh of a label scene without features inside its chest wall, against the re-mesh as it
# was (CGAL's features at 60 deg everywhere), on the calls that still re-mesh a label scene: the
# heterogeneous phantom's 7 mm label scene at the balanced and fast presets, the 8 mm phantom's
# 5 mm label scene at balanced, and SfePy's label scenes at --cell-size 12. OLD: copies of
# 552c6ac's binaries and libraries (the re-mesh then was the same as at 1856a70 on these calls:
# each re-meshes under both rules and loses no label); NEW: this build. Each pair at once, one
# OpenMP thread each.
# Usage: BIN=<552c6ac's devel/lib/breast_tumour_registration> LIB=<its devel/lib> LSF=/tmp/lsf LINIT=/tmp/linit bash run_features.sh OUT
set -uo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
NEW="$REPO/build/ws/devel/lib/breast_tumour_registration"; OLD="${BIN:?}"; OLD_LIB="${LIB:?}"
LSF="${LSF:-/tmp/lsf}"; LINIT="${LINIT:-/tmp/linit}"; OUT="$1"
export OMP_NUM_THREADS=1
mkdir -p "$OUT"; rm -f "$OUT/rows.txt"
summary() {
  /usr/bin/python3 -c "
import json
r=json.load(open('$1'))
t=[x for x in r['tumours'] if x.get('centroid_distance_mm') is not None]
m=r['mesh']
print('tets=%d wall=%d worst=%.3f axis_pct=%.1f converged=%s' % (m['tetrahedra'], m['chest_wall_vertices'], max(x['centroid_distance_mm'] for x in t), max(abs(x['axis_ratio']/x['truth_axis_ratio']-1)*100 for x in t), r.get('converged')))" 2>/dev/null || echo "-"
}
pair() {  # pair NAME SCENE PRESET STEPS [ARGS]
  local name=$1 scene=$2 preset=$3 steps=$4; shift 4
  for side in old new; do
    (
      d="$OUT/$name/$preset/$side"; mkdir -p "$d"; s=$(date +%s.%N)
      if [ $side = old ]; then LD_LIBRARY_PATH="$OLD_LIB" "$OLD/btr_register" "$scene" -q -p "$preset" ${steps:+-s $steps} "$@" -o "$d/reg" > "$d/reg.log" 2>&1
      else "$NEW/btr_register" "$scene" -q -p "$preset" ${steps:+-s $steps} "$@" -o "$d/reg" > "$d/reg.log" 2>&1; fi
      rc=$?; e=$(date +%s.%N)
      echo "$name $preset $* $side rc=$rc $(summary "$d/reg/report.json") s=$(printf %.1f $(echo "$e - $s" | bc))" > "$d/row"
    ) &
  done
  wait
  cat "$OUT/$name/$preset"/{old,new}/row | tee -a "$OUT/rows.txt"
}
pair het_c7 "$LINIT/new/het_c7/scene/scene.yaml" balanced ""
pair het_c7 "$LINIT/new/het_c7/scene/scene.yaml" fast ""
pair p8_c5 "$LINIT/new/p8_c5/scene/scene.yaml" balanced landmarks,surface
for n in BR_1000 BR_3400 AR_1000 AR_3400; do pair "$n" "$LSF/$n/new/scene/scene.yaml" balanced "" --cell-size 12; done
