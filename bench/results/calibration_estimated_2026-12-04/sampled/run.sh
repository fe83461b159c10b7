#!/bin/bash
B=/tmp/calest_lib/breast_tumour_registration; export LD_LIBRARY_PATH=/tmp/calest_lib
O=/tmp/calest_s
mkdir -p $O
P=/tmp/cal/phantoms
( cd /tmp/sfest && $B/btr_calibration E1000/scene_estimated_regions.yaml --draws 3 --samples 16 -o $O/sf1000 > $O/sf1000.log 2>&1
  cd $P && $B/btr_calibration E332_nu0.4653/scene_estimated.yaml E466_nu0.4714/scene_estimated.yaml E654_nu0.4959/scene_estimated.yaml E917_nu0.4898/scene_estimated.yaml --draws 3 --samples 16 -o $O/phA > $O/phA.log 2>&1 ) &
( cd /tmp/sfest && $B/btr_calibration E3400/scene_estimated_regions.yaml --draws 3 --samples 16 -o $O/sf3400 > $O/sf3400.log 2>&1
  cd $P && $B/btr_calibration E1287_nu0.4837/scene_estimated.yaml E1806_nu0.4776/scene_estimated.yaml E2533_nu0.4592/scene_estimated.yaml --draws 3 --samples 16 -o $O/phB > $O/phB.log 2>&1 ) &
wait
