#!/usr/bin/python3
"""Peak memory boicp.register adds on large numpy clouds, read in place
(C-order float64) against copied (the same arrays in Fortran order), each
registration in its own process, the layouts alternated; prints a Markdown
row per layout with the median over the rounds. bench/README.md reports it.

    PYTHONPATH=build/python bench/python_memory.py [--data-root ../shared/data]
        [--copies 16] [--rounds 3]

The clouds are two consecutive KITTI scans, each repeated `copies` times
with 1 mm of seeded jitter (16 copies: about 2 million points a cloud).
"""
import argparse
import os
import statistics
import subprocess
import sys

ONE_RUN = r"""
import sys
import numpy as np
import boicp
data, copies, layout = sys.argv[1], int(sys.argv[2]), sys.argv[3]
rng = np.random.default_rng(1)
def cloud(name):
    scan = boicp.read_scan(f"{data}/kitti00/velodyne/{name}.bin")
    return np.vstack([scan + rng.normal(0.0, 1e-3, scan.shape) for _ in range(copies)])
source, target = cloud("000001"), cloud("000000")
if layout == "copied":
    source, target = np.asfortranarray(source), np.asfortranarray(target)
assert boicp._boicp._reads_in_place(source) == (layout == "in place")
def status_kb(field):
    with open("/proc/self/status") as f:
        return next(int(l.split()[1]) for l in f if l.startswith(field + ":"))
# Forget the peak of building the arrays (Linux: 5 resets VmHWM to VmRSS).
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")
before = status_kb("VmRSS")
result = boicp.register(source, target, threads=2)
added = status_kb("VmHWM") - before
print(len(source), source.nbytes + target.nbytes, added * 1024, result.answered_by)
"""


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    here = os.path.dirname(os.path.abspath(__file__))
    parser.add_argument("--data-root", default=os.path.join(here, "..", "..", "shared", "data"))
    parser.add_argument("--copies", type=int, default=16)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    if not os.path.isdir(os.path.join(args.data_root, "kitti00")):
        print(f"{args.data_root}/kitti00: not found (--data-root)", file=sys.stderr)
        return 77
    added = {"in place": [], "copied": []}
    for _ in range(args.rounds):
        for layout in added:
            done = subprocess.run([sys.executable, "-c", ONE_RUN, args.data_root,
                                   str(args.copies), layout],
                                  capture_output=True, text=True, check=False)
            if done.returncode != 0:
                print(done.stderr, file=sys.stderr)
                return 1
            points, array_bytes, peak, rung = done.stdout.split()
            added[layout].append(int(peak))
    print(f"{points} points a cloud, {int(array_bytes) / 1e6:.0f} MB of arrays, "
          f"answered by {rung}, {args.rounds} rounds")
    print("| layout | peak added by register (median MB) | range MB |")
    print("|---|---:|---|")
    for layout, peaks in added.items():
        print(f"| {layout} | {statistics.median(peaks) / 1e6:.0f} | "
              f"{min(peaks) / 1e6:.0f}-{max(peaks) / 1e6:.0f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
