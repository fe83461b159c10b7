"""Summarizes the plausibility flag of btr_experiments CSVs (issue 11): per body, how many
runs were flagged implausible, the smallest tumour error among them (a flag on a good result
would be a false alarm), and the largest error among the runs not flagged, by kind of run.
Usage: /usr/bin/python3 bench/summarize_plausibility.py NAME=results.csv [NAME=results.csv ...]"""
import csv, sys

print("| body | runs | flagged implausible | smallest error flagged [mm] | largest error not flagged [mm]: full method / thesis method without rigid step / partial methods | exit 0 with an error > 2 mm (converged, not flagged): all / without rigid step |")
print("|---|---|---|---|---|---|")
for arg in sys.argv[1:]:
    name, path = arg.split("=", 1)
    runs = {}
    for r in csv.DictReader(open(path)):
        k = (r["experiment"], r["setting"], r["variable"], r["value"], r["generating_youngs_modulus_Pa"])
        e = float(r["centroid_distance_mm"])
        runs.setdefault(k, [0.0, r["status"]])
        runs[k][0] = max(runs[k][0], e)
    flagged = [v[0] for v in runs.values() if "(implausible)" in v[1]]
    def largest(pred):
        es = [v[0] for k, v in runs.items() if pred(k) and "(implausible)" not in v[1]]
        return f"{max(es):.2f}" if es else "-"
    partial = lambda k: k[0] == "practical" and k[1] != "full"
    without = lambda k: k[1] == "without_rigid"
    full = lambda k: not partial(k) and not without(k)
    silent = [k for k, v in runs.items() if v[1] == "converged" and v[0] > 2.0]
    smallest = f"{min(flagged):.2f}" if flagged else "-"
    print(f"| {name} | {len(runs)} | {len(flagged)} | {smallest} | {largest(full)} / {largest(without)} / {largest(partial)} | "
          f"{len(silent)} / {sum(1 for k in silent if without(k))} |")
