"""Not-converged rate and tumour error of btr_experiments CSVs (issue 10), per body and
generating Young's modulus: runs, runs not converged (with the steps that stopped and why,
counted by kind), and the worst tumour centroid error of the full method (practical / full).
Usage: /usr/bin/python3 bench/summarize_convergence.py NAME=results.csv [NAME=results.csv ...]"""
import collections, csv, re, sys

print("| body | E [Pa] | runs | not converged | full method, worst tumour [mm] | median over all runs of the worst tumour [mm] |")
print("|---|---|---|---|---|---|")
reasons = collections.Counter()
for arg in sys.argv[1:]:
    name, path = arg.split("=", 1)
    runs = {}
    for r in csv.DictReader(open(path)):
        k = (r["experiment"], r["setting"], r["variable"], r["value"], r["generating_youngs_modulus_Pa"])
        e = float(r["centroid_distance_mm"]) if r["centroid_distance_mm"] not in ("", "nan") else float("inf")
        runs.setdefault(k, [0.0, r["status"]])
        runs[k][0] = max(runs[k][0], e)
    by_e = collections.defaultdict(list)
    for k, v in runs.items():
        by_e[float(k[4])].append((k, v))
    total = bad = 0
    for E in sorted(by_e):
        rows = by_e[E]
        nc = [(k, v) for k, v in rows if not v[1].startswith("converged")]
        for k, v in nc:
            why = re.sub(r"-?\d[\d.]*(e[-+]?\d+)?", "#", v[1].split(": ", 1)[-1])[:90]
            reasons[(name, k[0] + "/" + k[1], why)] += 1
        full = [v[0] for k, v in rows if k[0] == "practical" and k[1] == "full"]
        worst = sorted(v[0] for k, v in rows)
        med = worst[len(worst) // 2] if worst else float("nan")
        print(f"| {name} | {E:g} | {len(rows)} | {len(nc)} | {max(full) if full else float('nan'):.3f} | {med:.3f} |")
        total += len(rows)
        bad += len(nc)
    print(f"| {name} | all | {total} | {bad} ({100.0 * bad / max(total, 1):.0f} %) | | |")
print()
print("Not converged, by reason (numbers replaced by #):")
for (name, run, why), n in sorted(reasons.items(), key=lambda t: -t[1]):
    print(f"- {name}, {run}: {n} x {why}")
