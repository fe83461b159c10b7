#!/bin/bash
# The method on truth made by an independent FEM code (SfePy, P2, heterogeneous): generates the
# configurations (bench/make_independent_truth.py), registers each with the prone shape as rest
# (the thesis), unloaded at the assumed 3400 Pa, and unloaded at an estimated E, each homogeneous
# and (the last two) with the tissue regions, and prints a markdown table of the worst tumour
# error, then per fat E the tumours' shape (bench/summarize_tumours.py). Needs python3-sfepy and tetgen (Debian):
#   apt-get install -y python3-sfepy python3-petsc4py tetgen   (petsc4py: MUMPS, 20x faster than SuperLU)
# Usage: bash bench/run_independent_truth.sh OUT [fat E [Pa] ...]   (default 300 1000 3400)
set -euo pipefail
OUT=${1:?usage: run_independent_truth.sh OUT [fat E ...]}
shift || true
MODULI=${*:-300 1000 3400}
here=$(cd "$(dirname "$0")" && pwd)
set +u  # ROS's setup scripts read unset variables
source "$here/../build/ws/devel/setup.bash"
set -u
for E in $MODULI; do
  [ -f "$OUT/E$E/truth.json" ] || PYTHONUNBUFFERED=1 /usr/bin/python3 "$here/make_independent_truth.py" "$OUT" \
    --fat-youngs-moduli "$E" --max-volume "${MAX_VOLUME:-5000}"
  for v in prone unloaded estimated unloaded_regions estimated_regions estimated_regions_nodal; do
    rosrun breast_tumour_registration btr_register "$OUT/E$E/scene_$v.yaml" --quiet --out "$OUT/E$E/reg_$v" \
      > "$OUT/E$E/reg_$v.log" 2>&1 || true  # exit 4/5 (not converged / implausible) still writes the report
  done
done
/usr/bin/python3 - "$OUT" $MODULI <<'PY'
import json, sys, os
out, moduli = sys.argv[1], sys.argv[2:]
print('| fat E [Pa] | prone sag [mm] | rigid only [mm] | prone as rest [mm] | unloaded at 3400 Pa [mm] | unloaded at estimated E [mm] | estimated E [Pa] | seconds (estimated) |')
print('|---|---|---|---|---|---|---|---|')
for E in moduli:
    d = os.path.join(out, 'E' + E)
    truth = json.load(open(os.path.join(d, 'truth.json')))
    row, rigid, est, secs = {}, None, '-', '-'
    for v in ('prone', 'unloaded', 'estimated'):
        try:
            r = json.load(open(os.path.join(d, 'reg_' + v, 'report.json')))
        except (OSError, ValueError):
            row[v] = 'failed'
            continue
        worst = max(t['centroid_distance_mm'] for t in r['tumours'])
        row[v] = '%.3f%s' % (worst, '' if r['converged'] else '*')
        rigid = max(t['rigid_only_centroid_distance_mm'] for t in r['tumours'])
        if v == 'estimated':
            est = '%.0f' % r.get('stiffness', {}).get('estimated_youngs_modulus_Pa', float('nan'))
            secs = '%.1f' % r['seconds']['registration_total']
    print('| %s | %.1f | %s | %s | %s | %s | %s | %s |' % (E, truth['prone']['max_displacement_mm'],
          '%.2f' % rigid if rigid is not None else '-', row['prone'], row['unloaded'], row['estimated'], est, secs))
PY
for E in $MODULI; do
  d=$OUT/E$E
  echo "### fat E = $E Pa: tumour shape"
  /usr/bin/python3 "$here/summarize_tumours.py" $(for v in prone unloaded estimated unloaded_regions estimated_regions estimated_regions_nodal; do
    echo "$v=$d/reg_$v/report.json"; done)
done
