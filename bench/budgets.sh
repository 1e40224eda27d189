#!/usr/bin/env bash
# `boicp map` on one folder twice, with `--budget fixed` and with the default
# ladder, then the pair-by-pair comparison (bench/compare_budgets.py).
#
#   bench/budgets.sh FOLDER OUT [--truth FILE.kitti | --pairs pairs.csv] [--repeat N]
#                    [-- MAP FLAGS...]
#
# Writes OUT/fixed and OUT/auto (each a map run with map.json, the --json
# summary) and prints the comparison. With --repeat N the two runs alternate
# N times (OUT/fixed.2, OUT/auto.2, ...) and the wall-time ratio is the
# median of the rounds'. Uses build/bin/boicp (BIN overrides).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BIN:-$ROOT/build/bin/boicp}"
[ $# -ge 2 ] || { sed -n '2,12p' "$0"; exit 2; }
FOLDER="$1"; OUT="$2"; shift 2
REFERENCE=()
MAP_FLAGS=()
REPEAT=1
while [ $# -gt 0 ]; do
  case "$1" in
    --truth|--pairs) REFERENCE=("$1" "$2"); shift ;;
    --repeat) REPEAT="$2"; shift ;;
    --) shift; MAP_FLAGS=("$@"); break ;;
    *) echo "budgets.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
[[ "$REPEAT" =~ ^[1-9][0-9]*$ ]] || { echo "budgets.sh: --repeat needs a positive count" >&2; exit 2; }
ROUNDS=()
for round in $(seq 1 "$REPEAT"); do
  suffix=""
  if [ "$round" -gt 1 ]; then suffix=".$round"; fi
  for budget in fixed auto; do
    dir="$OUT/$budget$suffix"
    rm -rf "${dir:?}"
    mkdir -p "$dir"
    "$BIN" map "$FOLDER" -o "$dir" --budget "$budget" --json "${MAP_FLAGS[@]}" > "$dir/map.json"
  done
  if [ "$round" -gt 1 ]; then ROUNDS+=(--round "$OUT/fixed$suffix" "$OUT/auto$suffix"); fi
done
/usr/bin/python3 "$ROOT/bench/compare_budgets.py" "$OUT/fixed" "$OUT/auto" "${REFERENCE[@]}" \
  "${ROUNDS[@]}"
