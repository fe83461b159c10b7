#!/usr/bin/env bash
# The same btr_register calls two ways, side by side: on a copy of an earlier build's devel/lib
# (BEFORE_LIB, e.g. `cp -a build/ws/devel/lib /tmp/before` before the change) and on this build;
# or on this build twice, with each scene copied with a setting on one side or both
# (BEFORE_SETTING / AFTER_SETTING="key.path=value", e.g.
# AFTER_SETTING=material.unload_element_order=quadratic against the scene as it is). Each scene
# runs both ways at once (one OpenMP thread each), so a pair's seconds share the machine alike;
# the errors are deterministic.
# Usage: BEFORE_LIB=/tmp/before bash bench/compare_builds.sh OUT NAME=SCENE.yaml [NAME=SCENE.yaml ...]
#        AFTER_SETTING=material.unload_element_order=quadratic bash bench/compare_builds.sh OUT NAME=SCENE.yaml ...
#   EXTRA="--preset accurate" passes arguments to every call.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="$1"; shift
AFTER="$REPO/build/ws/devel/lib/breast_tumour_registration/btr_register"
if [ -n "${BEFORE_SETTING:-}${AFTER_SETTING:-}" ]; then
  BEFORE_LIB="${BEFORE_LIB:-$REPO/build/ws/devel/lib}"
else
  BEFORE_LIB="${BEFORE_LIB:?set BEFORE_LIB to a copy of an earlier build (devel/lib), or BEFORE_SETTING / AFTER_SETTING}"
fi
BEFORE="$BEFORE_LIB/breast_tumour_registration/btr_register"
export OMP_NUM_THREADS=1
copies=()
trap 'rm -f "${copies[@]}"' EXIT
# with_setting SCENE SIDE NAME SETTING: prints the scene to run (a copy beside it with the setting:
# its relative paths stay valid), or the scene itself without a setting
with_setting() {
  if [ -z "$4" ]; then echo "$1"; return; fi
  local copy
  copy="$(dirname "$1")/.$2_$3.yaml"
  /usr/bin/python3 - "$1" "$copy" "$4" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1]))
key, value = sys.argv[3].split('=', 1)
keys = key.split('.')
target = s
for k in keys[:-1]:
    target = target.setdefault(k, {})
target[keys[-1]] = yaml.safe_load(value)
yaml.safe_dump(s, open(sys.argv[2], 'w'))
PY
  echo "$copy"
}
mkdir -p "$OUT"
for spec in "$@"; do
  name="${spec%%=*}"; scene="${spec#*=}"
  before_scene="$(with_setting "$scene" before "$name" "${BEFORE_SETTING:-}")"
  after_scene="$(with_setting "$scene" after "$name" "${AFTER_SETTING:-}")"
  copies+=("$(dirname "$scene")/.before_$name.yaml" "$(dirname "$scene")/.after_$name.yaml")
  LD_LIBRARY_PATH="$BEFORE_LIB" "$BEFORE" "$before_scene" --out "$OUT/before/$name" -q ${EXTRA:-} > "$OUT/before_$name.log" 2>&1 &
  "$AFTER" "$after_scene" --out "$OUT/after/$name" -q ${EXTRA:-} > "$OUT/after_$name.log" 2>&1 &
  wait || true
done
/usr/bin/python3 - "$OUT" "$@" <<'PY'
import json, os, sys
out, specs = sys.argv[1], [s.split('=', 1)[0] for s in sys.argv[2:]]
print('| scene | worst tumour: before / after [mm] | converged | surface step: projections, held from | free-limit check (after) | seconds (preparation with meshing + registration) |')
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
    secs = lambda r: sum(r['seconds'].get(k, 0) for k in ('prepare', 'registration_total'))  # prepare includes the meshing
    print('| %s | %.3f / %.3f | %s / %s | %d, %d / %d, %d | %s | %.2f / %.2f |' % (
        n, w(b), w(a), conv(b), conv(a), sb['projections'], sb['sliding_held_from_projection'], sa['projections'],
        sa['sliding_held_from_projection'], check, secs(b), secs(a)))
PY
