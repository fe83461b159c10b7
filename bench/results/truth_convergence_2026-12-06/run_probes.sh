#!/bin/bash
# The forward-floor and decomposition probes of BENCHMARKS.md, "Is the independent truth converged?".
# P2=second body's P2 truth folder, P3=its --order 3 folder; FWD=the built bench/probes/forward_discrepancy.cpp.
# Usage: P2=B P3=B3 FWD=/tmp/fwd bash run_probes.sh > probes.txt
set -u
for E in 500 1000; do
  for T in "$P2" "$P3"; do
    cd "$T" || exit 1
    echo "== $T, fat $E Pa"
    for form in nodal element; do
      echo "-- $form, supine from the true rest shape (gravity only), own mesh / 7 / 5 mm"
      OMP_NUM_THREADS=1 "$FWD" model_regions.yaml truth.yaml $E $form 0 7 5 | grep -v '^\['
      echo "-- $form, prone from the true rest shape, 7 / 5 mm"
      PROBE_POSE=prone OMP_NUM_THREADS=1 "$FWD" model_regions.yaml truth.yaml $E $form 7 5 | grep -v '^\['
    done
    for R in rest unloaded estimated; do
      echo "-- nodal, the full plan from the $R shape, 7 mm"
      PROBE_REST=$R PROBE_STEPS=full OMP_NUM_THREADS=1 "$FWD" model_regions.yaml truth.yaml $E nodal 7 | grep -v '^\['
    done
  done
done
