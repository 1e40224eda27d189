#!/usr/bin/env python3
"""Fits the confidence model of core/src/registration/confidence.cpp on bench outcomes.

usage: fit_confidence.py --fit CSV [CSV...] --test CSV [CSV...]
       fit_confidence.py --check CSV [CSV...]
       fit_confidence.py --folds CSV [CSV...]

Every CSV is a boicp-bench results.csv. Rows of the BO methods (those with
the feature columns) are the samples, `success` the label. The model is a
logistic regression of success on fitness, the log of the margin and the
refinement's angular resolution, fitted by Newton's method with a small
ridge penalty on the --fit rows, and capped as the engine caps it (low
fitness, a near tie with a measured runner-up, points the target saw
through). It prints the weights as C++ constants,
then for the --test rows (never used in the fit): the AUROC, the share of
failures flagged doubtful (confidence < 0.95), the share of successes
flagged, and a reliability table. --check reports the same for the
confidence the engine itself recorded in the rows (the shipped model, final
answers after any retry), with no fit. --folds fits leave-one-dataset-out:
for each dataset, on every other dataset's rows, then tests on that one's;
it also reports the shipped model (the recorded confidence) per dataset.
The CSVs may be attempts.csv files, whose rows are every attempt of every
rung (prior, features, searches, retries), each judged on its own answer.
"""

import argparse
import csv
import math
import sys

import numpy as np

TRUSTED_FROM = 0.95  # kTrustedFrom in core/include/boicp/registration/bo_icp.hpp

# The results.csv also carries rmse_ratio, support and probability_better.
# They separated held-out runs no better, and the weights they took (support
# and P(better) positive) left flipped 7-Scenes pairs outside the fit at
# confidence 0.65-0.96. resolution_deg is what tells a fine fit at too
# coarse a refinement voxel (the bunny at the fixed settings, 2-3 degrees
# off) from a right answer: nothing else about those answers differs.
#
# The margin enters as a log: what marks a wrong answer is a near tie (two
# basins within a few per cent of each other's fitness), and a linear margin
# barely tells 2 % from 15 %. MARGIN_FLOOR is about the resolution of a
# fitness measured on thousands of points; it is kMarginFloor in confidence.cpp.
MARGIN_FLOOR = 0.01
FEATURES = {
    "kFitness": lambda row: float(row["fitness"]),
    "kLogMargin": lambda row: math.log(float(row["margin"]) + MARGIN_FLOOR),
    "kResolutionDeg": lambda row: float(row["resolution_deg"]),
}
RECORDED = {"confidence": lambda row: float(row["confidence"])}
# The engine trusts an answer at most in proportion to its fitness below this
# (kFitnessOfFullTrust in confidence.cpp); from no to full trust as a measured
# margin goes from the first to the second of MARGIN_TRUST (kMarginFloor,
# kMarginOfFullTrust); and from full to no trust as the share of its points
# the target's sensor saw through goes from the first to the second of
# SEEN_THROUGH_TRUST (kSeenThroughOfFullTrust, ...NoTrust). Predictions apply
# the same caps; none is fitted.
FITNESS_OF_FULL_TRUST = 0.1
MARGIN_TRUST = (MARGIN_FLOOR, 0.03)
SEEN_THROUGH_TRUST = (0.15, 0.3)
RIDGE = 1e-2  # keeps the weights finite when the fit rows are separable


def read_rows(paths):
    rows = []
    for path in paths:
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                if row["experiment"] == "suite" and row.get("fitness", "") != "":
                    rows.append(row)
    return rows


def as_samples(rows, features=FEATURES):
    samples = [[feature(row) for feature in features.values()] for row in rows]
    labels = [1.0 if row["success"] == "1" else 0.0 for row in rows]
    return np.array(samples).reshape(len(rows), len(features)), np.array(labels)


def read_samples(paths, features=FEATURES):
    return as_samples(read_rows(paths), features)


def fit_logistic(x, y):
    design = np.hstack([np.ones((len(x), 1)), x])
    w = np.zeros(design.shape[1])
    for _ in range(100):
        p = 1.0 / (1.0 + np.exp(-design @ w))
        gradient = design.T @ (p - y) + RIDGE * np.r_[0.0, w[1:]]
        hessian = design.T @ (design * (p * (1 - p))[:, None]) + RIDGE * np.diag(
            np.r_[0.0, np.ones(len(w) - 1)])
        step = np.linalg.solve(hessian, gradient)
        step *= min(1.0, 5.0 / max(np.abs(step).max(), 1e-12))  # damped: separable rows
        w -= step
        if np.abs(step).max() < 1e-10:
            break
    return w


def caps(rows):
    """Each row's cap from a near tie and from the share seen through. Files
    from before margin_measured was recorded take a margin above 0 as
    measured; from before seen_through, a share of 0."""
    margin = np.array([float(row["margin"]) for row in rows])
    measured = np.array([row["margin_measured"] == "1" if row.get("margin_measured")
                         else float(row["margin"]) > 0 for row in rows])
    none, full = MARGIN_TRUST
    tie_cap = np.where(measured, np.clip((margin - none) / (full - none), 0.0, 1.0), 1.0)
    seen = np.array([float(row.get("seen_through") or 0.0) for row in rows])
    full, none = SEEN_THROUGH_TRUST
    return np.minimum(tie_cap, np.clip((none - seen) / (none - full), 0.0, 1.0))


def predict(w, x, cap):
    model = 1.0 / (1.0 + np.exp(-(w[0] + x @ w[1:])))
    return np.minimum.reduce([model, np.maximum(x[:, 0], 0.0) / FITNESS_OF_FULL_TRUST, cap])


def auroc(scores, labels):
    positives, negatives = scores[labels == 1], scores[labels == 0]
    if len(positives) == 0 or len(negatives) == 0:
        return float("nan")
    wins = (positives[:, None] > negatives[None, :]).sum()
    ties = (positives[:, None] == negatives[None, :]).sum()
    return (wins + 0.5 * ties) / (len(positives) * len(negatives))


def report(p, y_test):
    failures, successes = y_test == 0, y_test == 1
    print(f"AUROC {auroc(p, y_test):.3f}")
    if failures.any():
        print(f"failures flagged doubtful: {int((p[failures] < TRUSTED_FROM).sum())}/{int(failures.sum())}")
    print(f"successes flagged doubtful: {int((p[successes] < TRUSTED_FROM).sum())}/{int(successes.sum())}")
    print("\n| confidence | runs | mean confidence | success rate |\n|---|---:|---:|---:|")
    edges = [0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0001]
    for lo, hi in zip(edges[:-1], edges[1:]):
        inside = (p >= lo) & (p < hi)
        if inside.any():
            print(f"| {lo:.1f}-{min(hi, 1.0):.1f} | {int(inside.sum())} | {p[inside].mean():.3f} | "
                  f"{y_test[inside].mean():.3f} |")


def flagged(p, y):
    failures, successes = y == 0, y == 1
    return (f"{int((p[failures] < TRUSTED_FROM).sum())}/{int(failures.sum())} failures and "
            f"{int((p[successes] < TRUSTED_FROM).sum())}/{int(successes.sum())} successes flagged doubtful")


def folds(paths):
    rows = read_rows(paths)
    datasets = sorted({row["dataset"] for row in rows})
    print("| held out | runs | refit on the others | shipped model |\n|---|---:|---|---|")
    for held_out in datasets:
        fit_rows = [row for row in rows if row["dataset"] != held_out]
        test_rows = [row for row in rows if row["dataset"] == held_out]
        x_fit, y_fit = as_samples(fit_rows)
        x_test, y_test = as_samples(test_rows)
        shipped, _ = as_samples(test_rows, RECORDED)
        refit = (flagged(predict(fit_logistic(x_fit, y_fit), x_test, caps(test_rows)),
                         y_test)
                 if 0 < y_fit.sum() < len(y_fit) else
                 f"no fit: the other datasets have {int((1 - y_fit).sum())} failures")
        print(f"| {held_out} | {len(test_rows)} | {refit} | {flagged(shipped[:, 0], y_test)} |")


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--fit", nargs="+")
    parser.add_argument("--test", nargs="+")
    parser.add_argument("--check", nargs="+")
    parser.add_argument("--folds", nargs="+")
    args = parser.parse_args(argv)
    if args.folds:
        folds(args.folds)
        return
    if args.check:
        confidence, y_check = read_samples(args.check, RECORDED)
        if len(y_check) == 0:
            sys.exit("fit_confidence.py: no BO rows with features in the --check files")
        print(f"{len(y_check)} runs ({int((1 - y_check).sum())} failures), recorded confidence")
        report(confidence[:, 0], y_check)
        return
    if not args.fit or not args.test:
        sys.exit("fit_confidence.py: give --fit and --test, or --check")
    x_fit, y_fit = read_samples(args.fit)
    test_rows = read_rows(args.test)
    x_test, y_test = as_samples(test_rows)
    if len(y_fit) == 0 or len(y_test) == 0:
        sys.exit("fit_confidence.py: no BO rows with features in the --fit or --test files")
    w = fit_logistic(x_fit, y_fit)
    print(f"fitted on {len(y_fit)} runs ({int((1 - y_fit).sum())} failures)")
    print(f"constexpr double kIntercept = {w[0]:.4g};")
    for name, weight in zip(FEATURES, w[1:]):
        print(f"constexpr double {name} = {weight:.4g};")

    print(f"\ntested on {len(y_test)} other runs ({int((1 - y_test).sum())} failures)")
    report(predict(w, x_test, caps(test_rows)), y_test)


if __name__ == "__main__":
    main(sys.argv[1:])
