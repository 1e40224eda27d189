#!/usr/bin/env bash
# The peak memory of the fusion bomb's shape (one scan fused twice) against
# the estimate boicpd and `boicp map` refuse maps by, over leaf sizes, ray
# lengths and thread counts, one process per configuration. Prints a
# Markdown table; bench/README.md reports it.
#
#   bench/fusion_memory.sh [--bin build/bin/boicp-fusion-memory-bench] [--data-root ../shared/data]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=$here/../build/bin/boicp-fusion-memory-bench
data_root=$here/../../shared/data
while [[ $# -gt 0 ]]; do
  case $1 in
    --bin) bin=$2; shift 2 ;;
    --data-root) data_root=$2; shift 2 ;;
    *) echo "usage: $0 [--bin PATH] [--data-root DIR]" >&2; exit 2 ;;
  esac
done
[[ -x $bin ]] || { echo "$bin: not built (cmake --build build --target boicp-fusion-memory-bench)" >&2; exit 2; }

# dataset  leaf sizes  ray cuts (0 = none)
grid=(
  "kitti00 0.4,0.2,0.1,0.05 0,20"
  "7scenes_redkitchen 0.05,0.02,0.01,0.005 0"
  "bunny 0.01,0.005,0.002,0.001 0"
)
rows=$(mktemp)
trap 'rm -f "$rows"' EXIT
for row in "${grid[@]}"; do
  read -r name leaves ranges <<<"$row"
  [[ -d $data_root/$name ]] || { echo "skipped $name: $data_root/$name is absent" >&2; continue; }
  for leaf in ${leaves//,/ }; do
    for range in ${ranges//,/ }; do
      for threads in 1 2; do
        "$bin" --data "$data_root/$name" --resolution "$leaf" --max-range "$range" \
          --threads "$threads" >>"$rows"
      done
    done
  done
done
/usr/bin/python3 - "$rows" <<'PY'
import json, sys
print("| data | leaf (m) | max range (m) | threads | cells marked | cells estimate "
      "| fusion MB | estimate MB | estimate / fusion |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
for line in open(sys.argv[1]):
    r = json.loads(line)
    name = r["data"].rstrip("/").split("/")[-1]
    ratio = r["bound_mb"] / max(r["fusion_mb"], 1e-9)
    print(f"| {name} | {r['resolution']:g} | {r['max_range']:g} | {r['threads']} "
          f"| {r['cells_marked']:.3g} | {r['cells_bound']:.3g} | {r['fusion_mb']:.0f} "
          f"| {r['bound_mb']:.0f} | {ratio:.1f} |")
PY
