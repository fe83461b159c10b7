#!/usr/bin/python3
"""Pareto front of the registration's speed/accuracy trade (CSV of btr_bench_tradeoff).

Usage: /usr/bin/python3 bench/plot_tradeoff.py tradeoff.csv [--out tradeoff.png]
Plots every swept setting (seconds per registration, median of the repeats, against the worst
tumour centroid error), draws the Pareto front (no other point is both faster and more
accurate) and marks the presets; prints the front as a Markdown table.
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    rows = list(csv.DictReader(open(a.csv)))
    for r in rows:
        r["s"] = float(r["seconds_median"])
        r["e"] = float(r["worst_error_mm"])
    front, best = [], float("inf")
    for r in sorted(rows, key=lambda r: (r["s"], r["e"])):
        if r["e"] < best:
            front.append(r)
            best = r["e"]
    fig, ax = plt.subplots(figsize=(8, 5))
    knobs = sorted({r["knob"] for r in rows})
    for k in knobs:
        sel = [r for r in rows if r["knob"] == k and r["knob"] != "preset"]
        if sel:
            ax.scatter([r["s"] for r in sel], [r["e"] for r in sel], s=18, alpha=0.6, label=k.replace("_", " "))
    ax.plot([r["s"] for r in front], [r["e"] for r in front], "k-", lw=1, label="Pareto front")
    for r in rows:
        if r["knob"] == "preset":
            ax.scatter([r["s"]], [r["e"]], marker="*", s=180, edgecolor="k", zorder=5)
            mesh = "scene mesh" if float(r["cell_size_mm"]) == 0 else f"{float(r['cell_size_mm']):g} mm mesh"
            ax.annotate(f"{r['value']} ({mesh})", (r["s"], r["e"]), textcoords="offset points", xytext=(6, 6))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("registration time per call [s] (median)")
    ax.set_ylabel("worst tumour centroid error [mm]")
    ax.set_title("Speed / accuracy of the registration (35k-tet ground truth)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    out = a.out or a.csv.rsplit(".", 1)[0] + ".png"
    fig.savefig(out, dpi=110)
    print(f"wrote {out}\n")
    print("| knob | value | base preset | cell [mm] | tets | seconds | worst error [mm] | mean error [mm] |")
    print("|---|---|---|---|---|---|---|---|")
    for r in front:
        cell = "scene" if float(r["cell_size_mm"]) == 0 else f"{float(r['cell_size_mm']):g}"
        print(f"| {r['knob']} | {r['value']} | {r['base_preset']} | {cell} | {r['tetrahedra']} | {r['s']:.3f} | "
              f"{r['e']:.3f} | {float(r['mean_error_mm']):.3f} |")


if __name__ == "__main__":
    main()
