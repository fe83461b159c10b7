#!/bin/bash
# Registers every phantom of make_phantoms.sh with the element and the nodal volume form (E estimated).
BIN=${BTR_BIN:-$(cd $(dirname $0)/../../.. && pwd)/build/ws/devel/lib/breast_tumour_registration}
cd "${1:?usage: register_both_forms.sh DIR}"
for d in E*_nu*/; do d=${d%/}
  for f in estimated estimated_nodal; do
    OMP_NUM_THREADS=1 $BIN/btr_register $d/scene_$f.yaml --out $d/out_$f -q > $d/out_$f.log 2>&1 &
  done
  wait
done
