#!/usr/bin/python3
"""The table of bench/objectives.sh: for each mode, seed, dataset and BO
method, the successes and median wall seconds with point-to-point and with
point-to-plane evaluations, then the successes summed over seeds and modes.

Usage: objectives_report.py DIR   (DIR holds MODE-OBJECTIVE-SEED/results.csv)
"""
import csv
import glob
import os
import statistics
import sys
from collections import defaultdict


def read_runs(folder):
    """Suite rows keyed by (mode, seed, dataset, method, objective)."""
    runs = defaultdict(list)
    for path in sorted(glob.glob(os.path.join(folder, "*-*-*", "results.csv"))):
        mode, objective, seed = os.path.basename(os.path.dirname(path)).split("-")
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                if row["experiment"] == "suite":
                    runs[(mode, seed, row["dataset"], row["method"], objective)].append(row)
    return runs


def successes(rows):
    return sum(row["success"] in ("1", "true") for row in rows)


def main():
    runs = read_runs(sys.argv[1])
    cases = sorted({key[:4] for key in runs})
    totals = defaultdict(lambda: [0, 0, 0])
    print("| mode | seed | dataset | method | success point | success plane "
          "| median s point | median s plane | plane / point |")
    print("|---|---|---|---|---:|---:|---:|---:|---:|")
    for case in cases:
        point, plane = runs.get(case + ("point",)), runs.get(case + ("plane",))
        if not point or not plane:
            continue
        t_point = statistics.median(float(r["wall_s"]) for r in point)
        t_plane = statistics.median(float(r["wall_s"]) for r in plane)
        print(f"| {' | '.join(case)} | {successes(point)}/{len(point)} "
              f"| {successes(plane)}/{len(plane)} | {t_point:.2f} | {t_plane:.2f} "
              f"| {t_plane / t_point:.2f} |")
        total = totals[case[2:]]
        total[0] += successes(point)
        total[1] += successes(plane)
        total[2] += len(point)
    print()
    print("| dataset | method | success point | success plane |")
    print("|---|---|---:|---:|")
    for (dataset, method), (point, plane, runs_of_case) in sorted(totals.items()):
        print(f"| {dataset} | {method} | {point}/{runs_of_case} | {plane}/{runs_of_case} |")


if __name__ == "__main__":
    main()
