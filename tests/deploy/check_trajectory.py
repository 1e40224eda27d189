#!/usr/bin/env python3
"""Compares a trajectory (KITTI format: one row-major 3x4 T_map_scan a line) with
reference poses, pair by pair, so a constant offset of the map frame does not matter.

Usage: check_trajectory.py TRAJECTORY.kitti --pairs-csv PAIRS.csv
       check_trajectory.py TRAJECTORY.kitti --truth TRUTH.kitti
  --pairs-csv  rows source,target,T_target_source (3x4) of consecutive scans
               (../shared/data/kitti00/pairs.csv); with N poses, the first N-1 rows
  --truth      the true T_map_scan of every scan (boicp demo-data's truth.kitti);
               the first N are used
Exits 1 when a consecutive pair is off by more than --max-rotation-deg or
--max-translation-m (defaults 2 degrees and 0.3 m: a correct registration).
"""

import argparse
import csv
import math
import sys


def read_kitti(path):
    poses = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            values = [float(v) for v in line.split()]
            if values:
                if len(values) != 12:
                    raise ValueError(f"{path}: a line has {len(values)} numbers, want 12")
                poses.append(to_matrix(values))
    return poses


def to_matrix(v):
    return [v[0:4], v[4:8], v[8:12], [0.0, 0.0, 0.0, 1.0]]


def multiply(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def inverse(t):
    r = [[t[j][i] for j in range(3)] for i in range(3)]
    p = [-sum(r[i][k] * t[k][3] for k in range(3)) for i in range(3)]
    return [r[0] + [p[0]], r[1] + [p[1]], r[2] + [p[2]], [0.0, 0.0, 0.0, 1.0]]


def error(estimate, reference):
    """Rotation angle (degrees) and translation length (m) of estimate^-1 * reference."""
    d = multiply(inverse(estimate), reference)
    cosine = max(-1.0, min(1.0, (d[0][0] + d[1][1] + d[2][2] - 1.0) / 2.0))
    return math.degrees(math.acos(cosine)), math.sqrt(sum(d[i][3] ** 2 for i in range(3)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trajectory")
    reference = parser.add_mutually_exclusive_group(required=True)
    reference.add_argument("--pairs-csv")
    reference.add_argument("--truth")
    parser.add_argument("--max-rotation-deg", type=float, default=2.0)
    parser.add_argument("--max-translation-m", type=float, default=0.3)
    args = parser.parse_args()

    poses = read_kitti(args.trajectory)
    if len(poses) < 2:
        print(f"{args.trajectory}: {len(poses)} poses, want at least 2")
        return 1
    # T_target_source of each consecutive pair (source i, target i+1).
    if args.truth:
        truth = read_kitti(args.truth)
        if len(truth) < len(poses):
            print(f"{args.trajectory}: {len(poses)} poses, the truth has only {len(truth)}")
            return 1
        references = [multiply(inverse(truth[i + 1]), truth[i]) for i in range(len(poses) - 1)]
    else:
        with open(args.pairs_csv, encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
        if len(rows) < len(poses) - 1:
            print(f"{args.pairs_csv}: {len(rows)} pairs, the trajectory needs {len(poses) - 1}")
            return 1
        names = ["r00", "r01", "r02", "t0", "r10", "r11", "r12", "t1", "r20", "r21", "r22", "t2"]
        references = [to_matrix([float(row[n]) for n in names]) for row in rows[: len(poses) - 1]]

    failures = 0
    for i, reference_pose in enumerate(references):
        estimate = multiply(inverse(poses[i + 1]), poses[i])
        degrees, metres = error(estimate, reference_pose)
        ok = degrees <= args.max_rotation_deg and metres <= args.max_translation_m
        failures += not ok
        print(f"pair {i}->{i + 1}: rotation {degrees:.3f} deg, translation {metres:.3f} m"
              f"{'' if ok else '  FAIL'}")
    print(f"{len(references) - failures} of {len(references)} pairs within "
          f"{args.max_rotation_deg} deg and {args.max_translation_m} m")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
