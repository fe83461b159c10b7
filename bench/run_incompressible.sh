#!/usr/bin/env bash
# Near incompressibility (issue 11): the worst tumour error, landmark residual and time of the
# balanced preset when the method's Poisson's ratio approaches 0.5, with the element and the
# nodal-averaged volume term, on phantoms generated at 4.7 mm (truth) with either form.
# Usage: bench/run_incompressible.sh [OUT]  (after scripts/setup.sh). Table on stdout.
set -euo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="${1:-$REPO_ROOT/out/incompressible}"
B="$REPO_ROOT/build/ws/devel/lib/breast_tumour_registration"
mkdir -p "$OUT"
# Truth: the thesis's nu = 0.49 with the element form (the default phantom), and nu = 0.4999
# with the nodal form.
[ -f "$OUT/t049/scene.yaml" ] || "$B/btr_phantom" -q --out "$OUT/t049" --cell-size 4.7 --poisson-ratio 0.49 --volume-form element >/dev/null
[ -f "$OUT/t04999/scene.yaml" ] || "$B/btr_phantom" -q --out "$OUT/t04999" --cell-size 4.7 --poisson-ratio 0.4999 --volume-form nodal >/dev/null
echo "| truth | method nu | volume form | worst tumour error [mm] | landmark residual max [mm] | seconds | exit code |"
echo "|---|---|---|---|---|---|---|"
run() {  # truth dir, method nu, form
  local d="$OUT/$1" nu="$2" form="$3" tag="$1_${2}_$3"
  /usr/bin/python3 - "$d/scene.yaml" "$d/scene_$tag.yaml" "$nu" "$form" <<'PY'
import sys, yaml
s = yaml.safe_load(open(sys.argv[1]))
s['material']['poisson_ratio'] = float(sys.argv[3])
s['material']['volume_form'] = sys.argv[4]
yaml.safe_dump(s, open(sys.argv[2], 'w'))
PY
  set +e
  "$B/btr_register" "$d/scene_$tag.yaml" --out "$OUT/reg_$tag" -q --preset balanced >"$OUT/reg_$tag.log" 2>&1
  local rc=$?
  set -e
  /usr/bin/python3 - "$OUT/reg_$tag/report.json" "$1" "$nu" "$form" "$rc" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
worst = max(t["centroid_distance_mm"] for t in r["tumours"])
print(f"| {sys.argv[2]} | {sys.argv[3]} | {sys.argv[4]} | {worst:.3f} | {r['landmark_residual_mm']['max']:.2f} | {r['seconds']['registration_total']:.2f} | {sys.argv[5]} |")
PY
}
for nu in 0.49 0.499 0.4999 0.49999; do for form in element nodal; do run t049 $nu $form; done; done
for form in element nodal; do run t04999 0.4999 $form; done
