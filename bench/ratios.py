#!/usr/bin/env python3
"""Pair-by-pair wall-time ratios of one benchmark run, appended to summary.md.

For every dataset: how many times longer `naive` and `ransac-fpfh` took than
`bo-C` on the same pair (median and minimum over the pairs both ran), and
the success of each. Only rows of the suite are used; the scaling rows are
timed alone and are not comparable.

usage: ratios.py OUT_DIR
"""

import csv
import os
import statistics
import sys
from collections import defaultdict

REFERENCE = "bo-C"
OTHERS = ["naive", "ransac-fpfh", "bo-A"]


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    folder = argv[1]
    rows = [r for r in csv.DictReader(open(os.path.join(folder, "results.csv")))
            if r["experiment"] == "suite" and not r["error"]]
    wall = defaultdict(dict)  # (dataset, method) -> {pair: seconds}
    success = defaultdict(int)
    for r in rows:
        wall[(r["dataset"], r["method"])][(r["source"], r["target"])] = float(r["wall_s"])
        success[(r["dataset"], r["method"])] += int(r["success"])
    lines = ["", "## Wall time against bo-C, pair by pair", "",
             "| dataset | method | pairs | median x bo-C | min x bo-C | success (method / bo-C) |",
             "|---|---|---:|---:|---:|---|"]
    for dataset in sorted({d for d, _ in wall}):
        reference = wall.get((dataset, REFERENCE), {})
        for method in OTHERS:
            other = wall.get((dataset, method), {})
            pairs = sorted(set(reference) & set(other))
            if not pairs:
                continue
            ratios = [other[p] / reference[p] for p in pairs if reference[p] > 0]
            lines.append(f"| {dataset} | {method} | {len(pairs)} | {statistics.median(ratios):.2f} | "
                         f"{min(ratios):.2f} | {success[(dataset, method)]} / "
                         f"{success[(dataset, REFERENCE)]} |")
    with open(os.path.join(folder, "summary.md"), "a") as summary:
        summary.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
