#!/usr/bin/env python3
"""Compares two `boicp map` runs of the same folder pair by pair: usually
`--budget fixed` against the default ladder.

usage: compare_budgets.py FIXED_OUT AUTO_OUT [--truth FILE.kitti | --pairs pairs.csv]
                          [--round FIXED_OUT AUTO_OUT ...]

Reads each run's pairs.json and map.json (what `boicp map --json` printed). Prints, for each run, the ICP
evaluations of all pairs, the wall time and the count per rung, then the
ratios, and for every pair whether the ladder's transform is within 1 cm and
0.1 degree of the fixed run's, or else closer to the reference: the drive's
true poses (--truth, one 3x4 row-major T_world_scan per line, as
`boicp demo-data` writes) or a pairs.csv of reference T_target_source (the
shared data's). Each --round is another pair of runs of the same folder,
made alternately with the first: the wall-time ratio is then the median of
every round's, and each round's transforms must equal the first's (the runs
are seeded). Exit status 1 when some pair is neither, or a round differs.
"""

import argparse
import json
import math
import os
import sys

import numpy as np

TRANSLATION_TOLERANCE_M = 0.01
ROTATION_TOLERANCE_DEG = 0.1


def load_run(folder):
    with open(os.path.join(folder, "pairs.json")) as f:
        pairs = json.load(f)
    with open(os.path.join(folder, "map.json")) as f:
        run = json.load(f)
    return {(p["source_path"], p["target_path"]): p for p in pairs}, run


def rotation_deg(T):
    cosine = (np.trace(T[:3, :3]) - 1.0) / 2.0
    return math.degrees(math.acos(max(-1.0, min(1.0, cosine))))


def difference(A, B):
    delta = np.linalg.inv(A) @ B
    return rotation_deg(delta), float(np.linalg.norm(delta[:3, 3]))


def homogeneous(numbers):
    T = np.eye(4)
    T[:3, :] = np.array(numbers, dtype=float).reshape(3, 4)
    return T


def references(args, pairs):
    """Reference T_target_source per pair key, from --truth or --pairs."""
    if args.truth:
        with open(args.truth) as f:
            poses = [homogeneous(line.split()) for line in f if line.strip()]
        names = sorted({os.path.basename(s) for key in pairs for s in key})
        index = {name: k for k, name in enumerate(names)}
        return {key: np.linalg.inv(poses[index[os.path.basename(key[1])]])
                @ poses[index[os.path.basename(key[0])]] for key in pairs}
    if args.pairs:
        refs = {}
        with open(args.pairs) as f:
            next(f)
            for line in f:
                fields = line.strip().split(",")
                refs[(os.path.basename(fields[0]), os.path.basename(fields[1]))] = homogeneous(
                    fields[2:])
        return {key: refs.get((os.path.basename(key[0]), os.path.basename(key[1])))
                for key in pairs}
    return {}


def rung_counts(pairs):
    counts = {}
    for p in pairs.values():
        rung = p.get("answered_by", "full-search")
        counts[rung] = counts.get(rung, 0) + 1
    return ", ".join(f"{n} {rung}" for rung, n in sorted(counts.items()))


def compare_rounds(rounds, fixed, auto, first_ratio):
    """Prints every round's wall times and the median ratio; counts the
    rounds whose transforms differ from the first's."""
    ratios = [first_ratio]
    differing = 0
    for k, (fixed_dir, auto_dir) in enumerate(rounds, start=2):
        round_fixed, fixed_run = load_run(fixed_dir)
        round_auto, auto_run = load_run(auto_dir)
        ratios.append(fixed_run["runtime_s"] / auto_run["runtime_s"])
        print(f"round {k}: wall fixed {fixed_run['runtime_s']:.1f} s, auto "
              f"{auto_run['runtime_s']:.1f} s, {ratios[-1]:.1f}x")
        for first, again in ((fixed, round_fixed), (auto, round_auto)):
            if any(again.get(key, {}).get("transform") != p["transform"]
                   for key, p in first.items()):
                print(f"round {k}: transforms differ from the first round's")
                differing += 1
    print(f"wall fixed / auto over {len(ratios)} rounds: median {float(np.median(ratios)):.1f}x "
          f"(range {min(ratios):.1f}-{max(ratios):.1f}x)")
    return differing


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("fixed")
    parser.add_argument("auto")
    parser.add_argument("--truth")
    parser.add_argument("--pairs")
    parser.add_argument("--round", nargs=2, action="append", default=[],
                        metavar=("FIXED_OUT", "AUTO_OUT"))
    args = parser.parse_args(argv)
    fixed, fixed_run = load_run(args.fixed)
    auto, auto_run = load_run(args.auto)
    refs = references(args, fixed)
    totals = {}
    for name, pairs, run in (("fixed", fixed, fixed_run), ("auto", auto, auto_run)):
        evaluations = sum(p["evaluations"] for p in pairs.values())
        wall = run["runtime_s"]
        totals[name] = (evaluations, wall)
        print(f"{name}: {len(pairs)} pairs, {evaluations} ICP evaluations, wall {wall:.1f} s, "
              f"{rung_counts(pairs)}")
    (fe, fw), (ae, aw) = totals["fixed"], totals["auto"]
    print(f"fixed / auto: evaluations {fe / max(ae, 1):.1f}x, wall {fw / aw:.1f}x")
    bad = compare_rounds(args.round, fixed, auto, fw / aw) if args.round else 0

    worst = (0.0, 0.0)
    for key, f in fixed.items():
        a = auto.get(key)
        if a is None:
            print(f"{key}: missing from the auto run")
            bad += 1
            continue
        rot, trans = difference(np.array(f["transform"]), np.array(a["transform"]))
        worst = (max(worst[0], rot), max(worst[1], trans))
        if rot <= ROTATION_TOLERANCE_DEG and trans <= TRANSLATION_TOLERANCE_M:
            continue
        ref = refs.get(key)
        verdict = "differs, no reference"
        if ref is not None:
            fixed_error = difference(ref, np.array(f["transform"]))
            auto_error = difference(ref, np.array(a["transform"]))
            closer = auto_error[0] <= fixed_error[0] and auto_error[1] <= fixed_error[1]
            verdict = ("closer to the reference" if closer else "FARTHER from the reference") + (
                f" (fixed {fixed_error[0]:.3f} deg {fixed_error[1]:.4f} m, "
                f"auto {auto_error[0]:.3f} deg {auto_error[1]:.4f} m)")
            if closer:
                print(f"{os.path.basename(key[0])} -> {os.path.basename(key[1])}: "
                      f"{rot:.3f} deg {trans:.4f} m from fixed, {verdict}")
                continue
        print(f"{os.path.basename(key[0])} -> {os.path.basename(key[1])}: "
              f"{rot:.3f} deg {trans:.4f} m from fixed, {verdict}")
        bad += 1
    print(f"largest difference from fixed: {worst[0]:.3f} deg, {worst[1]:.4f} m; "
          f"{bad} pairs neither within {TRANSLATION_TOLERANCE_M} m and "
          f"{ROTATION_TOLERANCE_DEG} deg nor closer to the reference")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
