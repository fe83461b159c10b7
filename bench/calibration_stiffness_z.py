#!/usr/bin/python3
"""Is the stiffness estimate's sd right? From btr_calibration CSVs of scenes that estimate E
(bench/run_calibration.sh with BTR_CAL_STIFFNESS=estimate): per scene, the generating E taken
from its path (phantoms: .../E917_nu0.4898/..., independent truth: .../independent_truth_E1000/...,
the fat's modulus), and per noisy copy z = ln(E_estimated / E_true) / sd(ln E). The mean of
ln(E / E_true) is the bias that model error leaves (a Poisson's ratio or tissue the method does
not have); the sd of ln(E) over the copies is the landmark noise's share, which the sd should match.
Usage: /usr/bin/python3 bench/calibration_stiffness_z.py A/calibration.csv [B/calibration.csv ...]
"""
import csv
import math
import re
import statistics
import sys
from collections import OrderedDict


def true_e(path):
    m = re.search(r"(?:^|/)E(\d+)(?:_nu[0-9.]+)?/", path) or re.search(r"independent_truth_E(\d+)/", path)
    return float(m.group(1)) if m else None


def main():
    per = OrderedDict()
    for path in sys.argv[1:]:
        with open(path) as f:
            for r in csv.DictReader(f):
                # One value per copy: its tumours' rows repeat it.
                per.setdefault(r["scene"], OrderedDict())[r["draw"]] = (float(r["youngs_modulus_Pa"]), float(r["youngs_modulus_log_sd"]))
    print("| scene | true E | copies | median E | mean ln(E/E_true) | sd of ln E over copies | median sd(ln E) | rms z |")
    print("|---|---|---|---|---|---|---|---|")
    all_z = []
    for scene, copies in per.items():
        e0 = true_e(scene)
        vals = [v for v in copies.values() if v[1] > 0]
        if not e0 or not vals:
            continue
        d = [math.log(e / e0) for e, _ in vals]
        z = [di / s for di, (_, s) in zip(d, vals)]
        all_z += z
        spread = statistics.stdev(d) if len(d) > 1 else float("nan")
        print(f"| {scene} | {e0:.0f} | {len(vals)} | {statistics.median([e for e, _ in vals]):.0f} | {statistics.mean(d):+.3f} | "
              f"{spread:.3f} | {statistics.median([s for _, s in vals]):.3f} | {math.sqrt(statistics.mean([x * x for x in z])):.2f} |")
    if all_z:
        print(f"\nall copies: {len(all_z)}, rms z {math.sqrt(statistics.mean([x * x for x in all_z])):.2f}, "
              f"|z| <= 1.96 in {sum(abs(x) <= 1.96 for x in all_z)} of {len(all_z)}")


if __name__ == "__main__":
    main()
