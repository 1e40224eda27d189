#!/usr/bin/env python3
"""Writes wider-baseline pairs of a shared dataset by chaining its reference pairs.

usage: wide_pairs.py DATASET_DIR OUT_DIR --steps N[,N...] [--reverse]

DATASET_DIR's pairs.csv (source, target, then T_target_source row-major 3x4)
holds chains where one pair's target is the next pair's source (KITTI scans
0 -> 1 -> 2 ...; the first pair listed for a source is its link). For every
N in --steps, each scan of a chain is paired with the scan N links further
on, with the product of the links' references as its reference; pairs the
dataset already has are left out. --reverse also writes every new pair the
other way round (and the dataset's own pairs reversed). The official
poses of these datasets are less accurate than their pairs' references
(KITTI's first 16 poses by 0.2-0.7 m, 7-Scenes' KinectFusion poses by
several centimetres on some pairs), hence the chains.

OUT_DIR/<name of DATASET_DIR>/ gets the new pairs.csv and links to the
dataset's files, so that `boicp-bench --pairs OUT_DIR/<name>/pairs.csv`
finds the dataset in its table. Wider pairs overlap less: they test the
confidence on answers that can fail.
"""

import argparse
import csv
import os
import sys

import numpy as np

FIELDS = ["r00", "r01", "r02", "t0", "r10", "r11", "r12", "t1", "r20", "r21", "r22", "t2"]


def read_links(path):
    """Every pair of a pairs.csv as (source, target, T_target_source), in order."""
    pairs = []
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            T = np.eye(4)
            T[:3, :] = np.array([float(row[k]) for k in FIELDS]).reshape(3, 4)
            pairs.append((row["source"], row["target"], T))
    return pairs


def chains(links):
    """Maximal paths source -> target -> ... through the links."""
    targets = {target for target, _ in links.values()}
    found = []
    for start in links:
        if start in targets:
            continue  # not the head of a chain
        chain = [start]
        while chain[-1] in links and len(chain) <= len(links):
            chain.append(links[chain[-1]][0])
        found.append(chain)
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dataset")
    parser.add_argument("out")
    parser.add_argument("--steps", required=True, help="links per pair, comma separated")
    parser.add_argument("--reverse", action="store_true", help="every pair the other way round too")
    args = parser.parse_args()

    root = os.path.abspath(args.dataset)
    pairs_csv = os.path.join(root, "pairs.csv")
    if not os.path.exists(pairs_csv):
        sys.exit(f"wide_pairs.py: {pairs_csv} not found")
    known = read_links(pairs_csv)
    links = {}
    for source, target, T in known:
        links.setdefault(source, (target, T))
    steps = [int(s) for s in args.steps.split(",")]

    out = os.path.join(args.out, os.path.basename(root))
    os.makedirs(out, exist_ok=True)
    for entry in os.listdir(root):
        link = os.path.join(out, entry)
        if entry != "pairs.csv" and not os.path.lexists(link):
            os.symlink(os.path.join(root, entry), link)

    existing = {(source, target) for source, target, _ in known}
    new = []
    for chain in chains(links):
        for step in steps:
            for first in range(len(chain) - step):
                T = np.eye(4)  # T_current_first, built link by link
                for k in range(first, first + step):
                    T = links[chain[k]][1] @ T
                if (chain[first], chain[first + step]) not in existing:
                    new.append((chain[first], chain[first + step], T))
    if args.reverse:
        new += [(target, source, np.linalg.inv(T)) for source, target, T in new + known]
    rows = [[source, target] + [f"{v:.9g}" for v in T[:3, :].ravel()] for source, target, T in new]
    with open(os.path.join(out, "pairs.csv"), "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["source", "target"] + FIELDS)
        writer.writerows(rows)
    print(f"wrote {len(rows)} pairs to {out}/pairs.csv")


if __name__ == "__main__":
    main()
