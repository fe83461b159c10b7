#!/usr/bin/env bash
# The same btr_register calls on two builds, side by side: a copy of an earlier build's
# devel/lib (BEFORE_LIB, e.g. `cp -a build/ws/devel/lib /tmp/before` before the change) and this
# build. Each scene runs on both at once (one OpenMP thread each), so a pair's seconds share
# the machine alike; the errors are deterministic.
# Usage: BEFORE_LIB=/tmp/before bash bench/compare_builds.sh OUT NAME=SCENE.yaml [NAME=SCENE.yaml ...]
#   EXTRA="--preset accurate" passes arguments to every call.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="$1"; shift
BEFORE_LIB="${BEFORE_LIB:?set BEFORE_LIB to a copy of an earlier build (devel/lib)}"
AFTER="$REPO/build/ws/devel/lib/breast_tumour_registration/btr_register"
BEFORE="$BEFORE_LIB/breast_tumour_registration/btr_register"
export OMP_NUM_THREADS=1
mkdir -p "$OUT"
for spec in "$@"; do
  name="${spec%%=*}"; scene="${spec#*=}"
  LD_LIBRARY_PATH="$BEFORE_LIB" "$BEFORE" "$scene" --out "$OUT/before/$name" -q ${EXTRA:-} > "$OUT/before_$name.log" 2>&1 &
  "$AFTER" "$scene" --out "$OUT/after/$name" -q ${EXTRA:-} > "$OUT/after_$name.log" 2>&1 &
  wait || true
done
/usr/bin/python3 - "$OUT" "$@" <<'PY'
import json, os, sys
out, specs = sys.argv[1], [s.split('=', 1)[0] for s in sys.argv[2:]]
print('| scene | worst tumour: before / after [mm] | converged | surface step: projections, held from | free-limit check (after) | seconds (registration) |')
print('|---|---|---|---|---|---|')
def load(side, n):
    f = '%s/%s/%s/report.json' % (out, side, n)
    return json.load(open(f)) if os.path.exists(f) else None
for n in specs:
    b, a = load('before', n), load('after', n)
    if not b or not a:
        print('| %s | no report (see %s/*_%s.log) | | | | |' % (n, out, n)); continue
    w = lambda r: max(t['centroid_distance_mm'] for t in r['tumours'])
    sb, sa = b['step_reports'][-1], a['step_reports'][-1]
    c = sa.get('free_limit_check')
    check = '%.3f mm at %d%s' % (c['distance_mm'], c['projection'], ', beyond' if c['beyond_tolerance'] else '') if c else 'not run'
    conv = lambda r: 'yes' if r['converged'] else 'NO'
    print('| %s | %.3f / %.3f | %s / %s | %d, %d / %d, %d | %s | %.2f / %.2f |' % (
        n, w(b), w(a), conv(b), conv(a), sb['projections'], sb['sliding_held_from_projection'], sa['projections'],
        sa['sliding_held_from_projection'], check, b['seconds']['registration_total'], a['seconds']['registration_total']))
PY
