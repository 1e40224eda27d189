#!/usr/bin/env python3
"""Success and flagged misses of the field-data suite, per condition.

usage: field_report.py OUT

OUT holds one boicp-bench run per field condition (bench/field.sh), in
OUT/<condition>/results.csv; OUT/clean is the suite as it is. For every
condition, dataset and method: the successes, the share of the clean run's
successes that remain, and how many misses the confidence called doubtful
(below 0.95, kTrustedFrom), which is what a user can act on.
"""

import csv
import os
import sys

TRUSTED_FROM = 0.95  # kTrustedFrom in core/include/boicp/registration/bo_icp.hpp

CONDITIONS = ["clean", "sector", "quarter", "far-returns", "tilt", "far-origin", "geo-origin"]


def read(path):
    with open(path, newline="") as f:
        return [row for row in csv.DictReader(f) if row["experiment"] == "suite"]


def tally(rows):
    """{(dataset, method): (pairs, successes, misses, misses flagged, successes flagged)}"""
    out = {}
    for row in rows:
        key = (row["dataset"], row["method"])
        pairs, wins, misses, flagged_misses, flagged_wins = out.get(key, (0, 0, 0, 0, 0))
        success = row["success"] == "1"
        doubtful = row["confidence"] != "" and float(row["confidence"]) < TRUSTED_FROM
        out[key] = (pairs + 1, wins + success, misses + (not success),
                    flagged_misses + (not success and doubtful),
                    flagged_wins + (success and doubtful))
    return out


def main(argv):
    if len(argv) != 2:
        sys.exit(__doc__.strip().splitlines()[2])
    runs = {c: tally(read(os.path.join(argv[1], c, "results.csv")))
            for c in CONDITIONS if os.path.exists(os.path.join(argv[1], c, "results.csv"))}
    clean = runs.get("clean", {})
    # The clean run may hold more methods than the conditions were run with.
    shown = {method for c, counts in runs.items() if c != "clean" for _, method in counts}
    print("| condition | dataset | method | success | of clean | misses flagged | successes flagged |")
    print("|---|---|---|---:|---:|---:|---:|")
    for condition, counts in runs.items():
        for (dataset, method), (pairs, wins, misses, flagged_misses, flagged_wins) in sorted(
                counts.items()):
            if shown and method not in shown:
                continue
            base = clean.get((dataset, method), (0, 0))[1]
            share = f"{100.0 * wins / base:.0f} %" if base else "-"
            print(f"| {condition} | {dataset} | {method} | {wins}/{pairs} | {share} | "
                  f"{flagged_misses}/{misses} | {flagged_wins}/{wins} |")


if __name__ == "__main__":
    main(sys.argv)
