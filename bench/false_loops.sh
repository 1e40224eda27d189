#!/usr/bin/env bash
# False loop candidates forced through verification: pairs that a drifted
# chain could propose as loops but that do not overlap, each registered by
# the ladder from the identity prior (the chain saying "same place"). None
# may come out trusted -> OUT/false_loops.csv and one closing line.
# Usage: bench/false_loops.sh OUT [--bin DIR] [--data-root DIR]
#   50 pairs of another dataset: each KITTI 00 scan onto 5 VLP-16 scans;
#   50 pairs of one drive with no overlap: VLP-16 scans 40-112 onto 300-348,
#   stretches the drive never revisits (its revisits.csv);
#   50 look-alike pairs: a generated street drive (demo-data --scans 150,
#   2 m a scan, 35 m range), scans 112-148 onto scans 72-104 m before them:
#   the same kind of street, never the same stretch.
set -euo pipefail
cd "$(dirname "$0")/.."

out="" bin="build/bin" data="../shared/data"
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --data-root) data="$2"; shift 2 ;;
    -*) echo "usage: bench/false_loops.sh OUT [--bin DIR] [--data-root DIR]" >&2; exit 2 ;;
    *) out="$1"; shift ;;
  esac
done
[ -n "$out" ] || { echo "usage: bench/false_loops.sh OUT [--bin DIR] [--data-root DIR]" >&2; exit 2; }
vlp="$data/vlp16_loop/pcd"
if [ ! -d "$vlp" ] || [ ! -d "$data/kitti00/velodyne" ]; then
  echo "bench/false_loops.sh: no KITTI or VLP-16 data under $data; nothing to measure" >&2
  exit 77
fi
mkdir -p "$out"
printf '1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n' >"$out/identity.txt"

street="$out/generated_street"
[ -f "$street/truth.kitti" ] || "$bin/boicp" demo-data --scans 150 -o "$street" >/dev/null

pairs=()
for kitti in "$data"/kitti00/velodyne/*.bin; do
  for scan in 000060 000120 000180 000320 000440; do pairs+=("another-dataset|$kitti|$vlp/$scan.pcd"); done
done
for i in $(seq 40 8 112); do
  for j in $(seq 300 12 348); do
    pairs+=("no-overlap|$(printf '%s/%06d.pcd' "$vlp" "$i")|$(printf '%s/%06d.pcd' "$vlp" "$j")")
  done
done
for i in $(seq 112 4 148); do
  for back in 36 40 44 48 52; do
    pairs+=("look-alike|$(printf '%s/scan_%03d.xyz' "$street" "$i")|$(printf '%s/scan_%03d.xyz' "$street" $((i - back)))")
  done
done

csv="$out/false_loops.csv"
echo "kind,source,target,confidence,answered_by,runtime_s" >"$csv"
done_count=0
for entry in "${pairs[@]}"; do
  IFS='|' read -r kind source target <<<"$entry"
  "$bin/boicp" register --source "$source" --target "$target" --prior "$out/identity.txt" \
    --json -q >"$out/last.json"
  python3 - "$out/last.json" "$kind" "$source" "$target" >>"$csv" <<'PY'
import json, os, sys
r = json.load(open(sys.argv[1]))
kind, source, target = sys.argv[2:5]
print(f"{kind},{os.path.basename(source)},{os.path.basename(target)},"
      f"{r['confidence']:.4f},{r['answered_by']},{r['runtime_s']:.2f}")
PY
  done_count=$((done_count + 1))
  echo "false_loops: $done_count/${#pairs[@]}" >&2
done
python3 - "$csv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
trusted = [r for r in rows if float(r["confidence"]) >= 0.95]  # kTrustedFrom
print(f"{len(trusted)} of {len(rows)} false loop candidates trusted; highest confidence "
      f"{max(float(r['confidence']) for r in rows):.3f}; median {statistics.median(float(r['runtime_s']) for r in rows):.1f} s a pair")
for r in trusted:
    print(f"  trusted: {r['kind']} {r['source']} -> {r['target']} ({r['confidence']}, {r['answered_by']})")
PY
