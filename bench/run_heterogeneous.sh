#!/bin/bash
# Heterogeneous tissue on our phantom (issue 13): soft phantoms (fat 400 Pa) with stiff tumours
# (10x), with and without a fibroglandular region (2x), registered by a homogeneous and by a
# heterogeneous model (the scene's label regions), at the thesis's 3400 Pa, at the generating E
# with the unload step, and with E estimated. Prints one table per phantom (bench/summarize_tumours.py).
# Usage: [FAT_E=400] [ELEMENT_ORDER=linear|quadratic] bash bench/run_heterogeneous.sh OUT [cell size mm, default 9]
# FAT_E: the fat's Young's modulus [Pa] (gland 2x, tumours 10x); ELEMENT_ORDER: the truth's
# elements (btr_phantom --element-order; quadratic: a truth the method's elements did not make).
set -euo pipefail
OUT=${1:?usage: run_heterogeneous.sh OUT [cell size mm]}
CELL=${2:-9}
FAT_E=${FAT_E:-400}
ELEMENT_ORDER=${ELEMENT_ORDER:-linear}
GLAND_E=$((2 * FAT_E))
TUMOUR_E=$((10 * FAT_E))
here=$(cd "$(dirname "$0")" && pwd)
set +u  # ROS's setup scripts read unset variables
source "$here/../build/ws/devel/setup.bash"
set -u
mkdir -p "$OUT"
variants() {  # DIR E: the scene variants beside the phantom's scene.yaml
  /usr/bin/python3 - "$1" "$2" <<'PY'
import sys, yaml
d, E = sys.argv[1], float(sys.argv[2])
base = yaml.safe_load(open(d + '/scene.yaml'))
mat = lambda e: {'youngs_modulus': e, 'poisson_ratio': 0.49, 'density': 1000.0}
for name, regions, e, unload in (('homogeneous_3400', False, 3400.0, False), ('regions_3400', True, 3400.0, False),
                                 ('homogeneous_told', False, E, True), ('regions_told', True, E, True),
                                 ('homogeneous_estimated', False, 'estimate', True), ('regions_estimated', True, 'estimate', True)):
    s = dict(base)
    if not regions:
        s.pop('regions', None)
    s['material'] = mat(e)
    if unload:
        s['prone_gravity'] = [0, 0, 9.81]
    yaml.safe_dump(s, open('%s/%s.yaml' % (d, name), 'w'))
PY
}
for P in "tumours:--tumour-youngs-modulus $TUMOUR_E" "gland_tumours:--gland-youngs-modulus $GLAND_E --tumour-youngs-modulus $TUMOUR_E"; do
  name=${P%%:*}; args=${P#*:}
  d=$OUT/$name
  [ -f "$d/scene.yaml" ] || rosrun breast_tumour_registration btr_phantom --out "$d" -E "$FAT_E" $args --cell-size "$CELL" \
    --element-order "$ELEMENT_ORDER" --quiet > "$OUT/$name.log"
  variants "$d" "$FAT_E"
  rows=()
  for v in homogeneous_3400 regions_3400 homogeneous_told regions_told homogeneous_estimated regions_estimated; do
    rosrun breast_tumour_registration btr_register "$d/$v.yaml" --quiet --out "$d/reg_$v" > "$d/reg_$v.log" 2>&1 || true
    rows+=("$v=$d/reg_$v/report.json")
  done
  echo "### $name (fat $FAT_E Pa, $args, $CELL mm, $ELEMENT_ORDER truth)"
  /usr/bin/python3 "$here/summarize_tumours.py" "${rows[@]}"
done
