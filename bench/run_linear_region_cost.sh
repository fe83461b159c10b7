#!/usr/bin/env bash
# What the linearised tumour region (issue 14) adds to a registration: each scene registered
# RUNS times with `--uncertainty linear`, one OpenMP thread; the medians of the registration's
# seconds (report.json seconds.registration_total: the steps, not the region) and of the
# region's own (uncertainty.seconds), and their ratio.
# SETTING="key.path=value" runs a copy of every scene with that setting (e.g.
# material.unload_element_order=quadratic); EXTRA passes arguments to every call.
# Usage: [SETTING=...] [RUNS=3] bash bench/run_linear_region_cost.sh OUT NAME=SCENE.yaml [NAME=SCENE.yaml ...]
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="$1"; shift
RUNS="${RUNS:-3}"
BIN="$REPO/build/ws/devel/lib/breast_tumour_registration/btr_register"
export OMP_NUM_THREADS=1
copies=()
trap 'rm -f "${copies[@]}"' EXIT
mkdir -p "$OUT"
for spec in "$@"; do
  name="${spec%%=*}"; scene="${spec#*=}"
  if [ -n "${SETTING:-}" ]; then
    copy="$(dirname "$scene")/.cost_${name}_$$.yaml"
    copies+=("$copy")
    /usr/bin/python3 - "$scene" "$copy" "$SETTING" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1]))
key, value = sys.argv[3].split('=', 1)
target = s
for k in key.split('.')[:-1]:
    target = target.setdefault(k, {})
target[key.split('.')[-1]] = yaml.safe_load(value)
yaml.safe_dump(s, open(sys.argv[2], 'w'))
PY
    scene="$copy"
  fi
  for r in $(seq 1 "$RUNS"); do
    "$BIN" "$scene" -q --out "$OUT/$name/linear_$r" --uncertainty linear ${EXTRA:-} > "$OUT/${name}_linear_$r.log" 2>&1 || true
  done
done
/usr/bin/python3 - "$OUT" "$RUNS" "$@" <<'PY'
import json, os, statistics, sys
out, runs, names = sys.argv[1], int(sys.argv[2]), [s.split('=', 1)[0] for s in sys.argv[3:]]
print('| scene | registration [s] | the region [s] | region / registration | 95 % radii [mm] | rest shape\'s response |')
print('|---|---|---|---|---|---|')
for n in names:
    def reports(kind):
        fs = ['%s/%s/%s_%d/report.json' % (out, n, kind, r) for r in range(1, runs + 1)]
        return [json.load(open(f)) for f in fs if os.path.exists(f)]
    l = reports('linear')
    if not l:
        print('| %s | no reports (see %s/%s_*.log) | | | | |' % (n, out, n)); continue
    tr = statistics.median(r['seconds']['registration_total'] for r in l)
    tu = statistics.median(r['uncertainty']['seconds'] for r in l)
    radii = [t['uncertainty']['radius_95_mm'] for t in l[-1]['tumours'] if t.get('uncertainty')]
    note = l[-1]['uncertainty']['note']
    resp = note[note.find('unloaded rest shape'):].split(')')[0] + ')' if 'unloaded rest shape' in note else 'rest shape held'
    print('| %s | %.2f | %.2f | %.2f | %.2f to %.2f | %s |' % (n, tr, tu, tu / tr, min(radii), max(radii), resp))
PY
