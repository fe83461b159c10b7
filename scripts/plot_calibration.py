#!/usr/bin/python3
"""The calibration plot of issue 14 from btr_calibration's CSVs: expected against observed
coverage of the tumour's sampled and linearised regions (with 95 % Wilson intervals), and per
scene the median 95 % radius beside the median error.

Usage: /usr/bin/python3 scripts/plot_calibration.py A/calibration.csv [B/calibration.csv ...] --out DIR
Writes DIR/calibration.png and DIR/calibration.md. Uses Debian's python3-matplotlib only.
"""
import argparse
import csv
import math
import os
import re
import statistics

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LEVELS = [0.05 * k for k in range(1, 20)] + [0.99]


def wilson(k, n, z=1.959964):
    if n == 0:
        return (0.0, 1.0)
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (max(0.0, c - h), min(1.0, c + h))


def coverage(rows, key, level):
    vals = [float(r[key]) for r in rows if r[key] not in ("nan", "")]
    vals = [v for v in vals if not math.isnan(v)]
    k = sum(v <= level for v in vals)
    return (k / len(vals) if vals else float("nan"), *wilson(k, len(vals)), len(vals))


def scene_label(path):
    m = re.search(r"E(\d+)_nu([0-9.]+)", path)
    if m:
        return f"phantom E {m.group(1)} Pa, nu {m.group(2)}"
    m = re.search(r"independent_truth_E(\d+)/scene_(\w+)\.yaml", path)
    if m:
        return f"SfePy fat {m.group(1)} Pa, {m.group(2)}"
    return os.path.basename(os.path.dirname(path)) + "/" + os.path.basename(path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv", nargs="+")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    studies = []
    for path in a.csv:
        with open(path) as f:
            rows = list(csv.DictReader(f))
        studies.append((os.path.basename(os.path.dirname(os.path.abspath(path))), rows))
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
    ax = axes[0]
    ax.plot([0, 1], [0, 1], color="grey", lw=1, ls="--", label="calibrated")
    ax.axhspan(0.90, 0.99, xmin=0.9, xmax=1.0, color="green", alpha=0.15, label="issue 14's 90-99 % at 95 %")
    md = ["# Calibration of the tumour's uncertainty regions (btr_calibration)", ""]
    colours = ["tab:blue", "tab:orange", "tab:green", "tab:red"]
    for i, (name, rows) in enumerate(studies):
        # Since the discretisation source (2026-12-06): the sampled region also without it.
        split = "sampled_rank_sources" in rows[0] and any(r["discretisation_mm"] not in ("nan", "") for r in rows)
        forms = [("sampled_rank", "sampled", "-"), ("linear_level", "linear", ":")]
        if split:
            forms.insert(1, ("sampled_rank_sources", "sampled, sources only", "--"))
        for key, form, ls in forms:
            obs = [coverage(rows, key, p) for p in LEVELS]
            if all(math.isnan(o[0]) for o in obs):
                continue
            ax.plot(LEVELS, [o[0] for o in obs], ls=ls, marker="o", ms=3, color=colours[i % 4], label=f"{name}, {form}")
            ax.fill_between(LEVELS, [o[1] for o in obs], [o[2] for o in obs], color=colours[i % 4], alpha=0.12)
        md += [f"## {name}: {len(rows)} rows", "",
               "| level | sampled: observed [95 % interval] | linear: observed [95 % interval] |"
               + (" sampled, sources only (no discretisation) |" if split else ""),
               "|---|---|---|" + ("---|" if split else "")]
        for p in (0.5, 0.68, 0.8, 0.9, 0.95, 0.99):
            s, l = coverage(rows, "sampled_rank", p), coverage(rows, "linear_level", p)
            line = f"| {p:.2f} | {s[0]:.3f} [{s[1]:.3f}, {s[2]:.3f}] | {l[0]:.3f} [{l[1]:.3f}, {l[2]:.3f}] |"
            if split:
                o = coverage(rows, "sampled_rank_sources", p)
                line += f" {o[0]:.3f} [{o[1]:.3f}, {o[2]:.3f}] |"
            md.append(line)
        md += ["", "| scene | rows | median error [mm] | median 95 % radius sampled / linear [mm] | held at 95 % sampled / linear | samples not converged |"
               + (" median discretisation shift / sources-only radius [mm] |" if split else ""),
               "|---|---|---|---|---|---|" + ("---|" if split else "")]
        by = {}
        for r in rows:
            by.setdefault(r["scene"], []).append(r)
        for scene, rs in by.items():
            med = lambda k: statistics.median(float(r[k]) for r in rs)  # noqa: E731
            hs = sum(float(r["sampled_rank"]) <= 0.95 for r in rs)
            hl = sum(float(r["linear_level"]) <= 0.95 for r in rs)
            nc = sum(int(r["samples_not_converged"]) for r in rs[:: max(1, len(set(r["tumour"] for r in rs)))])
            ns = sum(int(r["samples"]) for r in rs[:: max(1, len(set(r["tumour"] for r in rs)))])
            line = (f"| {scene_label(scene)} | {len(rs)} | {med('error_mm'):.3f} | {med('sampled_radius_95_mm'):.3f} / "
                    f"{med('linear_radius_95_mm'):.3f} | {hs} / {hl} | {nc} of {ns} |")
            if split:
                line += f" {med('discretisation_mm'):.3f} / {med('sampled_radius_95_sources_mm'):.3f} |"
            md.append(line)
        md.append("")
    ax.set_xlabel("expected coverage (level of the region)")
    ax.set_ylabel("observed coverage (share of tumours held)")
    ax.set_title("Calibration of the tumour's region")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1.02)
    ax.legend(fontsize=8, loc="upper left")
    ax = axes[1]
    k = 0
    ticks = []
    for i, (name, rows) in enumerate(studies):
        by = {}
        for r in rows:
            by.setdefault(r["scene"], []).append(r)
        for scene, rs in by.items():
            e = statistics.median(float(r["error_mm"]) for r in rs)
            s = statistics.median(float(r["sampled_radius_95_mm"]) for r in rs)
            lv = [float(r["linear_radius_95_mm"]) for r in rs if r["linear_radius_95_mm"] != "nan"]
            ax.bar(k - 0.27, e, 0.27, color="black", label="median error" if k == 0 else None)
            ax.bar(k, s, 0.27, color=colours[i % 4], label=f"{name}: median sampled 95 % radius" if scene == next(iter(by)) else None)
            if lv:
                ax.bar(k + 0.27, statistics.median(lv), 0.27, color=colours[i % 4], alpha=0.4,
                       label=f"{name}: median linear 95 % radius" if scene == next(iter(by)) else None)
            ticks.append(scene_label(scene))
            k += 1
    ax.set_xticks(range(len(ticks)))
    ax.set_xticklabels(ticks, rotation=60, ha="right", fontsize=7)
    ax.set_ylabel("mm")
    ax.set_yscale("log")
    ax.set_title("Per scene: the error and the 95 % radius")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "calibration.png"), dpi=110)
    with open(os.path.join(a.out, "calibration.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print("\n".join(md))


if __name__ == "__main__":
    main()
