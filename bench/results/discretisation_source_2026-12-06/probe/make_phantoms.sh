#!/bin/bash
# quadratic-truth phantoms of the calibration study, scenes estimated (element / nodal)
BIN=${BTR_BIN:-$(cd $(dirname $0)/../../.. && pwd)/build/ws/devel/lib/breast_tumour_registration}
cd "${1:?usage: make_phantoms.sh DIR}"
while read E NU; do
  d=E${E}_nu${NU}
  [ -f $d/scene.yaml ] || OMP_NUM_THREADS=1 $BIN/btr_phantom -o $d -E $E --poisson-ratio $NU --cell-size 8 --element-order quadratic -q > $d.log 2>&1 || { echo fail $d; continue; }
  sed -e '/^material:/,/^[a-z]/ s/^  youngs_modulus: 3400$/  youngs_modulus: estimate/' $d/scene.yaml > $d/scene_estimated.yaml
  echo "prone_gravity: [0, 0, 9.81]" >> $d/scene_estimated.yaml
  sed -e 's/^  youngs_modulus: estimate$/  youngs_modulus: estimate\n  volume_form: nodal/' $d/scene_estimated.yaml > $d/scene_estimated_nodal.yaml
  echo made $d
done <<'X'
654 0.4959
917 0.4898
1287 0.4837
1806 0.4776
2533 0.4592
X
