#!/usr/bin/python3
"""The scale table of bench/scale.sh: one row per run (the latest of each
mode and drive length), each stage's share of wall time, and the exponent b
of a least-squares fit log(time) = a + b log(scans) per mode, for the whole
run and per stage (b = 1 is linear). Draws time and memory against scans on
log-log axes into --png when matplotlib is installed.

Usage: scale_report.py RUNS_CSV [--threads T] [--config P] [--png FILE]
"""
import argparse
import csv
import math


def latest_runs(path):
    """The last row of each (mode, scans), numbers as floats."""
    runs = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            key = (row["mode"], int(row["scans"]))
            runs[key] = {k: (v if k == "mode" else float(v)) for k, v in row.items()}
    return [runs[k] for k in sorted(runs)]


def loglog_slope(xs, ys):
    """Least-squares slope of log(y) on log(x); None with fewer than 2 points."""
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if x > 0 and y > 0]
    if len(pts) < 2:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx if sxx > 0 else None


def share(part, whole):
    return f"{100.0 * part / whole:.0f} %" if whole > 0 else "-"


def fmt_slope(value):
    return "-" if value is None else f"{value:.2f}"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("runs")
    ap.add_argument("--threads", default="?")
    ap.add_argument("--config", default="?")
    ap.add_argument("--png", default="")
    args = ap.parse_args()
    runs = latest_runs(args.runs)

    print(f"Generated drives, config {args.config}, {args.threads} threads "
          "(`boicp map --threads`, boicpd `--workers`).\n")
    print("| mode | scans | wall s | pairs/min | fusion scans/s | peak RSS MB | map.bt MB "
          "| map.ot MB | upload | register | fuse | other |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in runs:
        wall = r["wall_s"]
        ppm = 60.0 * r["pairs"] / r["register_s"] if r["register_s"] > 0 else float("nan")
        fps = r["scans"] / r["fuse_s"] if r["fuse_s"] > 0 else float("nan")
        print(f"| {r['mode']} | {r['scans']:.0f} | {wall:.0f} | {ppm:.1f} | {fps:.1f} "
              f"| {r['peak_rss_mb']:.0f} | {r['bt_bytes'] / 1e6:.1f} | {r['ot_bytes'] / 1e6:.1f} "
              f"| {share(r['upload_s'], wall)} | {share(r['register_s'], wall)} "
              f"| {share(r['fuse_s'], wall)} | {share(r['other_s'], wall)} |")

    print("\nExponent b of time (and memory) against scans, log-log least squares:\n")
    print("| mode | drives | wall | register | fuse | peak RSS |")
    print("|---|---|---:|---:|---:|---:|")
    modes = sorted({r["mode"] for r in runs})
    for mode in modes:
        rows = [r for r in runs if r["mode"] == mode]
        xs = [r["scans"] for r in rows]
        slopes = [loglog_slope(xs, [r[k] for r in rows])
                  for k in ("wall_s", "register_s", "fuse_s", "peak_rss_mb")]
        drives = ", ".join(f"{x:.0f}" for x in xs)
        print(f"| {mode} | {drives} | " + " | ".join(fmt_slope(s) for s in slopes) + " |")

    if not args.png:
        return
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("\n(no matplotlib: no figure)")
        return
    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(10, 4))
    for mode in modes:
        rows = [r for r in runs if r["mode"] == mode]
        xs = [r["scans"] for r in rows]
        ax_t.loglog(xs, [r["wall_s"] for r in rows], "o-", label=f"{mode} wall")
        ax_t.loglog(xs, [r["fuse_s"] for r in rows], "s--", label=f"{mode} fusion")
        ax_m.loglog(xs, [r["peak_rss_mb"] for r in rows], "o-", label=mode)
    ax_t.set(xlabel="scans", ylabel="seconds", title="time")
    ax_m.set(xlabel="scans", ylabel="MB", title="peak RSS")
    for ax in (ax_t, ax_m):
        ax.legend()
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.png, dpi=100)
    print(f"\nfigure: {args.png}")


if __name__ == "__main__":
    main()
