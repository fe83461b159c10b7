#!/usr/bin/python3
"""Plots of the experiment suite (btr_experiments) in the style of the thesis's figures, and
the table of the thesis's reported ranges beside ours (summary.md).

Usage: /usr/bin/python3 scripts/plot_experiments.py RESULTS.csv [--out DIR]
Writes practical.png (Fig. 5.4), rest_shape.png (5.5), rotated_gravity.png (5.7a),
misalignment.png (5.9), material.png (5.10), landmark_weight.png (5.11),
landmark_set.png (5.12b) and summary.md into DIR (default: beside the CSV).
Uses Debian's python3-matplotlib and python3-numpy only.
"""
import argparse
import collections
import csv
import math
import os
import statistics

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

# What the thesis reports (Sec. 5.2 and the discussion, Ch. 6), per experiment and setting.
THESIS = {
    ("practical", "rigid"): "0.5 - 19.8",
    ("practical", "landmarks"): "0.0 - 9.0",
    ("practical", "surface"): "0.3 - 5.7",
    ("practical", "gravity+surface"): "0.0 - 5.4",
    ("practical", "full"): "0.0 - 1.0",
    ("rest_shape", "prone"): "mean < 1.0 for most E; 2.5 at E = 200",
    ("rest_shape", "rest"): "mean < 1.0",
    ("rotated_gravity", "full"): "spread about 1.0 at every angle",
    ("misalignment/without_rigid", "rotation_x_deg"): "up to 17.5",
    ("misalignment/without_rigid", "rotation_z_deg"): "up to 8.0",
    ("misalignment/without_rigid", "translation_x_mm"): "up to 2.1",
    ("misalignment/without_rigid", "translation_z_mm"): "up to 7.1",
    ("material", "full"): "up to 3.5 (soft generating E), 1.7 (stiff)",
    ("landmark_weight", "full"): "1e4 and 1e5 best, similar",
    ("landmark_set", "C+O"): "max 1.0",
    ("landmark_set", "O+Oa"): "max 0.3",
    ("landmark_set", "other sets"): "< 1.0",
}


def load(path):
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            for k in ("centroid_distance_mm", "hausdorff_mm", "volume_ratio", "seconds", "generating_youngs_modulus_Pa"):
                r[k] = float(r[k])
            rows.append(r)
    return rows


def ok(r):
    return not r["status"].startswith("failed") and math.isfinite(r["centroid_distance_mm"])


def numeric(v):
    try:
        return float(v)
    except ValueError:
        return None


def ordered_values(rows):
    vals = list(dict.fromkeys(r["value"] for r in rows))
    if all(numeric(v) is not None for v in vals):
        vals.sort(key=float)
    return vals


def boxplot(ax, groups, labels, title, xlabel):
    data = [[d for d in g] or [float("nan")] for g in groups]
    ax.boxplot(data, labels=labels, showfliers=False)
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("tumour centroid distance [mm]")
    ax.grid(axis="y", alpha=0.3)


def by(rows, **match):
    return [r for r in rows if all(r[k] == v for k, v in match.items())]


def dist(rows):
    return [r["centroid_distance_mm"] for r in rows if ok(r)]


def runs(rows):
    return len({(r["setting"], r["variable"], r["value"], r["generating_youngs_modulus_Pa"]) for r in rows})


def describe(sel):
    values = dist(sel)
    failed = runs([r for r in sel if not ok(r)])
    not_converged = runs([r for r in sel if r["status"].startswith("not_converged")])
    if not values:
        return "-", f"{failed} of {runs(sel)} runs failed"
    med = statistics.median(values)
    notes = []
    if failed:
        notes.append(f"{failed} of {runs(sel)} runs failed")
    if not_converged:
        notes.append(f"{not_converged} of {runs(sel)} runs not converged")
    return f"{min(values):.2f} - {max(values):.2f} (median {med:.2f})", ", ".join(notes) or "-"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    out = a.out or os.path.dirname(os.path.abspath(a.csv))
    os.makedirs(out, exist_ok=True)
    rows = load(a.csv)
    written = []

    def save(fig, name):
        fig.tight_layout()
        p = os.path.join(out, name)
        fig.savefig(p, dpi=110)
        plt.close(fig)
        written.append(p)

    ex = collections.defaultdict(list)
    for r in rows:
        ex[r["experiment"]].append(r)

    if ex["practical"]:
        order = ["rigid", "landmarks", "surface", "gravity+surface", "full"]
        order = [s for s in order if by(ex["practical"], setting=s)]
        fig, ax = plt.subplots(figsize=(7, 4))
        boxplot(ax, [dist(by(ex["practical"], setting=s)) for s in order], order,
                "Practical settings (thesis Fig. 5.4)", "method")
        save(fig, "practical.png")

    if ex["rest_shape"]:
        fig, ax = plt.subplots(figsize=(7, 4))
        for v in ordered_values(ex["rest_shape"]):
            sel = [r for r in by(ex["rest_shape"], value=v) if ok(r)]
            es = sorted({r["generating_youngs_modulus_Pa"] for r in sel})
            ax.plot(es, [statistics.mean(r["centroid_distance_mm"] for r in sel if r["generating_youngs_modulus_Pa"] == e)
                         for e in es], "o-", label=f"{v} shape as rest shape")
        ax.set_xscale("log")
        ax.set_xlabel("generating Young's modulus [Pa]")
        ax.set_ylabel("mean centroid distance over tumours [mm]")
        ax.set_title("Rest shape (thesis Fig. 5.5)")
        ax.legend()
        ax.grid(alpha=0.3)
        save(fig, "rest_shape.png")

    for name, title, xlabel in [("rotated_gravity", "Rotated gravity (thesis Fig. 5.7a)", "rotation of gravity about X [deg]"),
                                ("landmark_weight", "Landmark weight (thesis Fig. 5.11)", "landmark weight [N/m]"),
                                ("landmark_set", "Landmark sets (thesis Fig. 5.12b)", "landmarks")]:
        if ex[name]:
            vals = ordered_values(ex[name])
            fig, ax = plt.subplots(figsize=(7, 4))
            boxplot(ax, [dist(by(ex[name], value=v)) for v in vals], vals, title, xlabel)
            save(fig, name + ".png")

    if ex["misalignment"]:
        variables = [v for v in ["rotation_x_deg", "rotation_z_deg", "translation_x_mm", "translation_z_mm"]
                     if by(ex["misalignment"], variable=v)]
        fig, axes = plt.subplots(len(variables), 1, figsize=(9, 3.2 * len(variables)), squeeze=False)
        for ax, var in zip(axes[:, 0], variables):
            sel = by(ex["misalignment"], variable=var)
            vals = ordered_values(sel)
            pos = np.arange(len(vals))
            for k, (setting, colour) in enumerate([("without_rigid", "tab:red"), ("with_rigid", "tab:blue")]):
                data = [dist(by(sel, value=v, setting=setting)) or [float("nan")] for v in vals]
                b = ax.boxplot(data, positions=pos + (k - 0.5) * 0.35, widths=0.3, showfliers=False, patch_artist=True)
                for patch in b["boxes"]:
                    patch.set_facecolor(colour)
                    patch.set_alpha(0.5)
                ax.plot([], [], color=colour, lw=6, alpha=0.5, label=setting.replace("_", " ") + " step")
            ax.set_xticks(pos)
            ax.set_xticklabels(vals)
            ax.set_xlabel(var.replace("_", " ").replace(" deg", " [deg]").replace(" mm", " [mm]"))
            ax.set_ylabel("centroid distance [mm]")
            ax.grid(axis="y", alpha=0.3)
            ax.legend(loc="best")
        axes[0, 0].set_title("Misalignment of the supine scan (thesis Fig. 5.9)")
        save(fig, "misalignment.png")

    if ex["material"]:
        sel = [r for r in ex["material"] if ok(r)]
        xs = sorted({float(r["value"]) for r in ex["material"]})
        ys = sorted({r["generating_youngs_modulus_Pa"] for r in ex["material"]})
        grid = np.full((len(ys), len(xs)), np.nan)
        for i, y in enumerate(ys):
            for j, x in enumerate(xs):
                d = [r["centroid_distance_mm"] for r in sel if r["generating_youngs_modulus_Pa"] == y and float(r["value"]) == x]
                if d:
                    grid[i, j] = statistics.mean(d)
        fig, ax = plt.subplots(figsize=(8, 6))
        finite = grid[np.isfinite(grid)]
        norm = matplotlib.colors.LogNorm(vmin=max(0.01, finite.min()), vmax=max(0.02, finite.max())) if finite.size else None
        im = ax.imshow(grid, origin="lower", cmap="viridis", aspect="auto", norm=norm)
        ax.set_xticks(range(len(xs)))
        ax.set_xticklabels([f"{x:g}" for x in xs], rotation=60)
        ax.set_yticks(range(len(ys)))
        ax.set_yticklabels([f"{y:g}" for y in ys])
        ax.set_xlabel("Young's modulus of the method [Pa]")
        ax.set_ylabel("generating Young's modulus [Pa]")
        ax.set_title("Material (thesis Fig. 5.10): mean centroid distance [mm], log colour scale")
        for i in range(len(ys)):
            for j in range(len(xs)):
                if np.isfinite(grid[i, j]):
                    ax.text(j, i, f"{grid[i, j]:.2g}", ha="center", va="center", fontsize=6, color="w")
        fig.colorbar(im, ax=ax)
        save(fig, "material.png")

    # The comparison table.
    lines = ["| experiment | setting / value | thesis [mm] | ours, every E [mm] | ours, E >= 600 Pa: max [mm] | notes |",
             "|---|---|---|---|---|---|"]

    def row(experiment, label, sel, thesis):
        text, notes = describe(sel)
        firm = dist([r for r in sel if r["generating_youngs_modulus_Pa"] >= 600])
        lines.append(f"| {experiment} | {label} | {thesis} | {text} | {max(firm):.2f} |" if firm else
                     f"| {experiment} | {label} | {thesis} | {text} | - |")
        lines[-1] += f" {notes} |"

    for s in ["rigid", "landmarks", "surface", "gravity+surface", "full"]:
        if by(ex["practical"], setting=s):
            row("practical settings", s, by(ex["practical"], setting=s), THESIS[("practical", s)])
    for v in ["prone", "rest"]:
        if by(ex["rest_shape"], value=v):
            row("rest shape", f"{v} shape as rest", by(ex["rest_shape"], value=v), THESIS[("rest_shape", v)])
    for v in ordered_values(ex["rotated_gravity"]) if ex["rotated_gravity"] else []:
        row("rotated gravity", f"{v} deg", by(ex["rotated_gravity"], value=v), THESIS[("rotated_gravity", "full")])
    for var in ["rotation_x_deg", "rotation_z_deg", "translation_x_mm", "translation_z_mm"]:
        for setting in ["without_rigid", "with_rigid"]:
            sel = by(ex["misalignment"], variable=var, setting=setting)
            if sel:
                thesis = THESIS[("misalignment/without_rigid", var)] if setting == "without_rigid" else "(the thesis has no rigid step)"
                row("misalignment", f"{var.replace('_', ' ')}, {setting.replace('_', ' ')} step", sel, thesis)
    if ex["material"]:
        row("material", "all method E x generating E", ex["material"], THESIS[("material", "full")])
        diag = [r for r in ex["material"] if float(r["value"]) == r["generating_youngs_modulus_Pa"]]
        row("material", "method E = generating E", diag, "-")
    for v in ordered_values(ex["landmark_weight"]) if ex["landmark_weight"] else []:
        row("landmark weight", f"{float(v):g} N/m", by(ex["landmark_weight"], value=v), THESIS[("landmark_weight", "full")])
    for v in ordered_values(ex["landmark_set"]) if ex["landmark_set"] else []:
        row("landmark set", v, by(ex["landmark_set"], value=v), THESIS.get(("landmark_set", v), THESIS[("landmark_set", "other sets")]))
    moduli = sorted({r["generating_youngs_modulus_Pa"] for r in rows})
    head = (f"{len(rows)} rows from {os.path.basename(a.csv)}: generating E = "
            f"{', '.join(f'{e:g}' for e in moduli)} Pa; every tumour of every run counted. "
            "Failed runs have no figures (e.g. a prone mesh with a flat element); runs not converged are counted "
            "in the figures (a step stopped at its iteration budget).")
    with open(os.path.join(out, "summary.md"), "w") as f:
        f.write(head + "\n\n" + "\n".join(lines) + "\n")
    written.append(os.path.join(out, "summary.md"))
    for p in written:
        print(p)


if __name__ == "__main__":
    main()
