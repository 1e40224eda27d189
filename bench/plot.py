#!/usr/bin/env python3
"""Draws the benchmark figures from boicp-bench's results.csv.

usage: plot.py RESULTS_DIR   (reads RESULTS_DIR/results.csv, writes PNGs beside it)

Figures: box plots of rotation error, translation error and wall time per
method and dataset, histograms of the errors, and bo-C's scaling study.
Uses Debian's python3-matplotlib and nothing else.
"""

import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")  # files only: no display on CI or the benchmark machine
import matplotlib.pyplot as plt  # noqa: E402

METHOD_ORDER = ["bo-A", "bo-B", "bo-C", "bo-C-6dof", "naive", "icp-identity", "pyramid",
                "ransac-fpfh", "fgr"]
# BO variants in blues, the naive port in purple, baselines in warm colours.
COLOURS = {"bo-A": "#9ecae1", "bo-B": "#4292c6", "bo-C": "#08519c", "bo-C-6dof": "#17becf",
           "naive": "#7b4ea3", "icp-identity": "#969696", "pyramid": "#d62728",
           "ransac-fpfh": "#ff7f0e", "fgr": "#2ca02c"}
DPI = 100
# Errors of exactly zero cannot sit on a log axis; they are drawn at this floor.
FLOOR = {"rot_err_deg": 1e-3, "trans_err_m": 1e-5, "wall_s": 1e-3}
LABEL = {"rot_err_deg": "rotation error (deg)", "trans_err_m": "translation error (m)",
         "wall_s": "wall time per pair (s)"}


def number(text):
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def datasets_of(rows):
    names = []
    for row in rows:
        if row["dataset"] not in names:
            names.append(row["dataset"])
    return names


def methods_of(rows):
    present = {row["method"] for row in rows}
    return [m for m in METHOD_ORDER if m in present] + sorted(present - set(METHOD_ORDER))


def thresholds(summary_path):
    """Success thresholds per dataset, read back from summary.md."""
    result = {}
    if not os.path.exists(summary_path):
        return result
    with open(summary_path) as f:
        for line in f:
            if not line.startswith("- ") or "success <" not in line:
                continue
            name = line[2:].split(" ", 1)[0]
            tail = line.split("success <", 1)[1]
            try:
                rot = float(tail.split("deg")[0])
                trans = float(tail.split("and <", 1)[1].split("m")[0])
            except (IndexError, ValueError):
                continue
            result[name] = {"rot_err_deg": rot, "trans_err_m": trans}
    return result


def values(rows, dataset, method, column):
    out = []
    for row in rows:
        if row["dataset"] == dataset and row["method"] == method:
            v = number(row[column])
            if v is not None:
                out.append(max(v, FLOOR[column]))
    return out


def success_label(rows, dataset, method):
    runs = [r for r in rows if r["dataset"] == dataset and r["method"] == method]
    ok = sum(1 for r in runs if r["success"] == "1")
    return f"{method}\n{ok}/{len(runs)} ok"


def box_figure(rows, column, limits, path):
    datasets = datasets_of(rows)
    methods = methods_of(rows)
    fig, axes = plt.subplots(1, len(datasets), figsize=(4.6 * len(datasets), 4.8), squeeze=False)
    for ax, dataset in zip(axes[0], datasets):
        present = [m for m in methods if values(rows, dataset, m, column)]
        data = [values(rows, dataset, m, column) for m in present]
        box = ax.boxplot(data, patch_artist=True, widths=0.6, showfliers=True,
                         medianprops={"color": "black"},
                         flierprops={"marker": "o", "markersize": 3})
        for patch, method in zip(box["boxes"], present):
            patch.set_facecolor(COLOURS.get(method, "#cccccc"))
        for i, d in enumerate(data, start=1):  # every pair as a dot: few pairs per dataset
            ax.scatter([i] * len(d), d, s=6, color="black", alpha=0.5, zorder=3)
        ax.set_yscale("log")
        limit = limits.get(dataset, {}).get(column)
        if limit:
            ax.axhline(limit, color="red", linestyle="--", linewidth=1,
                       label=f"success < {limit:g}")
            ax.legend(loc="upper left", fontsize=8)
        labels = [success_label(rows, dataset, m) if column != "wall_s" else m for m in present]
        ax.set_xticks(range(1, len(present) + 1))
        ax.set_xticklabels(labels, rotation=60, ha="right", fontsize=8)
        ax.set_title(dataset)
        ax.set_ylabel(LABEL[column])
        ax.grid(axis="y", which="major", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def histogram_figure(rows, limits, path):
    datasets = datasets_of(rows)
    methods = methods_of(rows)
    columns = ["rot_err_deg", "trans_err_m"]
    fig, axes = plt.subplots(len(datasets), 2, figsize=(11, 3.2 * len(datasets)), squeeze=False)
    for r, dataset in enumerate(datasets):
        for c, column in enumerate(columns):
            ax = axes[r][c]
            all_values = [v for m in methods for v in values(rows, dataset, m, column)]
            if not all_values:
                continue
            low = math.floor(math.log10(min(all_values)))
            high = math.ceil(math.log10(max(all_values))) + 1e-9
            bins = [10 ** (low + (high - low) * i / 24) for i in range(25)]
            present = [m for m in methods if values(rows, dataset, m, column)]
            ax.hist([values(rows, dataset, m, column) for m in present], bins=bins,
                    stacked=True, color=[COLOURS.get(m, "#cccccc") for m in present],
                    label=present, edgecolor="white", linewidth=0.4)
            ax.set_xscale("log")
            limit = limits.get(dataset, {}).get(column)
            if limit:
                ax.axvline(limit, color="red", linestyle="--", linewidth=1)
            ax.set_xlabel(LABEL[column])
            ax.set_ylabel("runs (stacked)")
            ax.set_title(f"{dataset}: {LABEL[column].split(' (')[0]}")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=min(len(labels), 9), fontsize=8,
               frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def reference(ax, x, x0, y0, power, style, label):
    """Dotted guide y = y0 (x / x0)^power over the range of x."""
    grid = [x[0] * (x[-1] / x[0]) ** (i / 20) for i in range(21)]
    ax.plot(grid, [y0 * (v / x0) ** power for v in grid], style, color="grey", linewidth=1,
            label=label)


def scaling_figure(rows, path):
    fig, (ax_points, ax_iter) = plt.subplots(1, 2, figsize=(11, 4.4))
    markers = ["o", "s", "^", "D"]
    for k, dataset in enumerate(datasets_of(rows)):
        marker = markers[k % len(markers)]
        first = k == 0
        for experiment, style, name in [("scaling-voxel", "-", "3000-pt evaluations"),
                                        ("scaling-voxel-all", "--", "all points")]:
            pts = sorted((int(r["source_points"]), number(r["wall_s"]), number(r["icp_s"]))
                         for r in rows if r["dataset"] == dataset and r["experiment"] == experiment)
            if not pts:
                continue
            x = [p[0] for p in pts]
            ax_points.plot(x, [p[1] for p in pts], style, marker=marker, color="#08519c",
                           label=f"{dataset} wall, {name}")
            ax_points.plot(x, [p[2] for p in pts], style, marker=marker, color="#ff7f0e",
                           label=f"{dataset} inside ICP, {name}")
            if experiment == "scaling-voxel-all" and pts[0][2]:
                reference(ax_points, x, x[0], pts[0][2], 1, ":",
                          "reference ~ points" if first else None)
        its = sorted((int(r["evaluations"]) / 2, number(r["wall_s"]), number(r["icp_s"]),
                      number(r["model_s"]))
                     for r in rows
                     if r["dataset"] == dataset and r["experiment"] == "scaling-iterations")
        if its:
            x = [p[0] for p in its]
            ax_iter.plot(x, [p[1] for p in its], "-", marker=marker, color="#08519c",
                         label=f"{dataset} wall")
            ax_iter.plot(x, [p[2] for p in its], "-", marker=marker, color="#ff7f0e",
                         label=f"{dataset} inside ICP")
            ax_iter.plot(x, [p[3] for p in its], "-", marker=marker, color="#2ca02c",
                         label=f"{dataset} GP + acquisition")
            if its[0][2]:
                reference(ax_iter, x, x[0], its[0][2], 1, ":", "reference ~ n" if first else None)
            if its[0][3]:
                reference(ax_iter, x, x[0], its[0][3], 3, "--",
                          "reference ~ n^3" if first else None)
                reference(ax_iter, x, x[0], its[0][3], 4, "-.",
                          "reference ~ n^4 (n^3 per step, summed)" if first else None)
    for ax, xlabel in [(ax_points, "source points after downsampling"),
                       (ax_iter, "samples per stage n = N_r + N")]:
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("seconds")
        ax.grid(which="both", alpha=0.3)
        ax.legend(fontsize=7)
    ax_points.set_title("bo-C runtime vs points (fixed N)")
    ax_iter.set_title("bo-C runtime vs BO samples (fixed voxel)")
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    folder = argv[1]
    rows = read_rows(os.path.join(folder, "results.csv"))
    suite = [r for r in rows if r["experiment"] == "suite"]
    scaling = [r for r in rows if r["experiment"].startswith("scaling")]
    limits = thresholds(os.path.join(folder, "summary.md"))
    written = []
    if suite:
        for column, name in [("rot_err_deg", "box_rotation_error.png"),
                             ("trans_err_m", "box_translation_error.png"),
                             ("wall_s", "box_runtime.png")]:
            box_figure(suite, column, limits, os.path.join(folder, name))
            written.append(name)
        histogram_figure(suite, limits, os.path.join(folder, "hist_errors.png"))
        written.append("hist_errors.png")
    if scaling:
        scaling_figure(scaling, os.path.join(folder, "scaling.png"))
        written.append("scaling.png")
    print("plot.py: wrote " + ", ".join(written) + " in " + folder)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
