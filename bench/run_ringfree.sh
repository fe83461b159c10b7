#!/usr/bin/env bash
# Registration without a rigid region (issue 10): the phantom with its chest ring removed,
# C+O landmarks, method E = generating E, balanced preset; the default plan (`steps: auto`),
# `steps: [landmarks, surface]` on the aligned pair, and the default plan on a scan
# misaligned by 15 deg / 10 mm (two ways), plus the phantom with its ring misaligned.
# Usage: bash bench/run_ringfree.sh [cell_size_mm] [out_dir]   (after scripts/setup.sh)
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$REPO/build/ws/devel/lib/breast_tumour_registration"
CELL="${1:-6}"
OUT="${2:-$REPO/out/ringfree}"
mkdir -p "$OUT"
for E in 400 1000 3400 12000; do
  [ -f "$OUT/ph$E/scene.yaml" ] || "$BIN/btr_phantom" -q --out "$OUT/ph$E" -E "$E" --cell-size "$CELL" > "$OUT/ph$E.log"
  /usr/bin/python3 - "$OUT/ph$E" "$E" <<'PY'
import re, sys
d, E = sys.argv[1], sys.argv[2]
ring = open(d + '/scene.yaml').read().replace('youngs_modulus: 3400\n', 'youngs_modulus: %s\n' % E, 1)
s = re.sub(r'(?m)^\s*chest_ring: chest_ring.obj\n', '', ring)
variants = {
  'noring': s,
  'noring_ls': s.replace('steps: auto', 'steps: [landmarks, surface]'),
  'noring_mis1': s + 'misalignment: {rotation_deg: [15, 0, 0], translation_mm: [0, 0, 10]}\n',
  'noring_mis2': s + 'misalignment: {rotation_deg: [0, 0, 15], translation_mm: [10, 0, 0]}\n',
  'ring_mis2': ring + 'misalignment: {rotation_deg: [0, 0, 15], translation_mm: [10, 0, 0]}\n',
}
for k, v in variants.items():
    open('%s/%s.yaml' % (d, k), 'w').write(v)
PY
  for v in noring noring_ls noring_mis1 noring_mis2 ring_mis2; do
    "$BIN/btr_register" "$OUT/ph$E/$v.yaml" --out "$OUT/r_${E}_$v" > "$OUT/r_${E}_$v.log" 2>&1 || true
  done
done
/usr/bin/python3 - "$OUT" <<'PY'
import json, sys, os
out = sys.argv[1]
print('| E [Pa] | scene | worst tumour error [mm] | rigid-only [mm] | seconds | steps (converged, stop) | ICP vs joint pose [mm] |')
print('|---|---|---|---|---|---|---|')
for E in (400, 1000, 3400, 12000):
    for v in ('noring', 'noring_ls', 'noring_mis1', 'noring_mis2', 'ring_mis2'):
        f = '%s/r_%d_%s/report.json' % (out, E, v)
        if not os.path.exists(f):
            print('| %d | %s | no report (see %s.log) | | | | |' % (E, v, f[:-12])); continue
        r = json.load(open(f))
        t = r['tumours']
        steps = '; '.join('%s %s, %s' % (s['step'], 'yes' if s['converged'] else 'NO', s['stop'][:60]) for s in r['step_reports'])
        print('| %d | %s | %.3f | %.1f | %.2f | %s | %.2f |' % (E, v, max(x['centroid_distance_mm'] for x in t),
              max(x['rigid_only_centroid_distance_mm'] for x in t), r['seconds']['registration_total'], steps,
              r['rigid_transform_supine_to_model']['icp_vs_landmark_pose_mm']))
PY
