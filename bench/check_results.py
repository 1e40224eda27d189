#!/usr/bin/env python3
"""Checks a benchmark output folder: every method ran on every dataset without
throwing, and every expected file is there and small enough to commit.

usage: check_results.py OUT_DIR METHOD[,METHOD...]
Exit 0 when all is well, 1 with one line per problem otherwise.
"""

import csv
import os
import sys

FILES = ["results.csv", "summary.md", "box_rotation_error.png", "box_translation_error.png",
         "box_runtime.png", "hist_errors.png"]
MAX_PNG_BYTES = 300 * 1024


def main(argv):
    if len(argv) != 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    folder, methods = argv[1], argv[2].split(",")
    problems = []
    for name in FILES:
        path = os.path.join(folder, name)
        if not os.path.isfile(path) or os.path.getsize(path) == 0:
            problems.append(f"missing or empty: {path}")
        elif name.endswith(".png") and os.path.getsize(path) > MAX_PNG_BYTES:
            problems.append(f"{path}: {os.path.getsize(path)} bytes, over {MAX_PNG_BYTES}")
    results = os.path.join(folder, "results.csv")
    if os.path.isfile(results):
        with open(results, newline="") as f:
            rows = list(csv.DictReader(f))
        suite = [r for r in rows if r["experiment"] == "suite"]
        datasets = sorted({r["dataset"] for r in suite})
        if not datasets:
            problems.append(f"{results}: no suite rows")
        for dataset in datasets:
            for method in methods:
                runs = [r for r in suite if r["dataset"] == dataset and r["method"] == method]
                if not runs:
                    problems.append(f"{dataset}: no row for {method}")
                for r in runs:
                    if r["error"]:
                        problems.append(f"{dataset} {r['source']} {method} threw: {r['error']}")
        if any(r["experiment"].startswith("scaling") for r in rows):
            scaling_png = os.path.join(folder, "scaling.png")
            if not os.path.isfile(scaling_png):
                problems.append(f"missing: {scaling_png}")
    for problem in problems:
        print("check_results: " + problem, file=sys.stderr)
    if not problems:
        print(f"check_results: {len(methods)} methods ran on every dataset; all files present")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
