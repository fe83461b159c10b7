#!/usr/bin/env bash
# Registration without a rigid region (issue 10): the phantom with its chest ring removed,
# C+O landmarks, method E = generating E, balanced preset; the default plan (`steps: auto`),
# the same steps told the pose (`[landmarks, surface]`, or `[unload, landmarks, surface]`) on
# the aligned pair, and the default plan on a scan misaligned by 15 deg / 10 mm (two ways),
# plus the phantom with its ring misaligned.
# Two models: `prone` (the thesis's: the prone shape as the rest shape) and `unload` (the scene
# states `prone_gravity`, so the rest shape is unloaded at the told E first).
# Usage: bash bench/run_ringfree.sh [cell_size_mm] [out_dir] [models]   (after scripts/setup.sh)
#   models: "prone" (default), "unload" or "prone unload"
#   MODULI="400 1000" chooses the generating moduli (default 400 1000 3400 12000)
#   TRUTH_ORDER=quadratic makes the phantoms' truth with 10-node tetrahedra (btr_phantom --element-order)
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$REPO/build/ws/devel/lib/breast_tumour_registration"
CELL="${1:-6}"
OUT="${2:-$REPO/out/ringfree}"
MODELS="${3:-prone}"
TRUTH_ORDER="${TRUTH_ORDER:-linear}"
MODULI="${MODULI:-400 1000 3400 12000}"
VARIANTS="noring noring_ls noring_mis1 noring_mis2 ring_mis2"
mkdir -p "$OUT"
for E in $MODULI; do
  if [ ! -f "$OUT/ph$E/scene.yaml" ] &&
     ! "$BIN/btr_phantom" -q --out "$OUT/ph$E" -E "$E" --cell-size "$CELL" --element-order "$TRUTH_ORDER" > "$OUT/ph$E.log" 2>&1; then
    echo "E = $E Pa: the phantom was not made ($(tail -1 "$OUT/ph$E.log"))" >&2; continue
  fi
  /usr/bin/python3 - "$OUT/ph$E" "$E" <<'PY'
import re, sys
d, E = sys.argv[1], sys.argv[2]
base = open(d + '/scene.yaml').read().replace('youngs_modulus: 3400\n', 'youngs_modulus: %s\n' % E, 1)
for model, extra, told in (('prone', '', '[landmarks, surface]'),
                           ('unload', 'prone_gravity: [0, 0, 9.81]\n', '[unload, landmarks, surface]')):
    ring = base + extra
    s = re.sub(r'(?m)^\s*chest_ring: chest_ring.obj\n', '', ring)
    variants = {
      'noring': s,
      'noring_ls': s.replace('steps: auto', 'steps: ' + told),
      'noring_mis1': s + 'misalignment: {rotation_deg: [15, 0, 0], translation_mm: [0, 0, 10]}\n',
      'noring_mis2': s + 'misalignment: {rotation_deg: [0, 0, 15], translation_mm: [10, 0, 0]}\n',
      'ring_mis2': ring + 'misalignment: {rotation_deg: [0, 0, 15], translation_mm: [10, 0, 0]}\n',
    }
    for k, v in variants.items():
        open('%s/%s_%s.yaml' % (d, model, k), 'w').write(v)
PY
  for m in $MODELS; do
    for v in $VARIANTS; do
      "$BIN/btr_register" "$OUT/ph$E/${m}_$v.yaml" --out "$OUT/r_${E}_${m}_$v" > "$OUT/r_${E}_${m}_$v.log" 2>&1 || true
    done
  done
done
/usr/bin/python3 - "$OUT" "$MODELS" "$VARIANTS" "$MODULI" <<'PY'
import json, sys, os
out, models, variants, moduli = sys.argv[1], sys.argv[2].split(), sys.argv[3].split(), [int(e) for e in sys.argv[4].split()]
print('| E [Pa] | model | scene | worst tumour error [mm] | rigid-only [mm] | seconds | steps (converged, stop) | volume form |')
print('|---|---|---|---|---|---|---|---|')
for E in moduli:
    for m in models:
        for v in variants:
            f = '%s/r_%d_%s_%s/report.json' % (out, E, m, v)
            if not os.path.exists(f):
                print('| %d | %s | %s | no report (see %s.log) | | | | |' % (E, m, v, f[:-12])); continue
            r = json.load(open(f))
            t = r['tumours']
            steps = '; '.join('%s %s, %s' % (s['step'], 'yes' if s['converged'] else 'NO', s['stop'][:60]) for s in r['step_reports'])
            form = r.get('material_model', {}).get('volume_form', '')
            print('| %d | %s | %s | %.3f | %.1f | %.2f | %s | %s |' % (E, m, v, max(x['centroid_distance_mm'] for x in t),
                  max(x['rigid_only_centroid_distance_mm'] for x in t), r['seconds']['registration_total'], steps, form))
PY
