#!/usr/bin/env bash
# `boicp map` on one folder twice, with `--budget fixed` and with the default
# ladder, then the pair-by-pair comparison (bench/compare_budgets.py).
#
#   bench/budgets.sh FOLDER OUT [--truth FILE.kitti | --pairs pairs.csv] [-- MAP FLAGS...]
#
# Writes OUT/fixed and OUT/auto (each a map run with map.json, the --json
# summary) and prints the comparison. Uses build/bin/boicp (BIN overrides).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BIN:-$ROOT/build/bin/boicp}"
[ $# -ge 2 ] || { sed -n '2,9p' "$0"; exit 2; }
FOLDER="$1"; OUT="$2"; shift 2
REFERENCE=()
MAP_FLAGS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --truth|--pairs) REFERENCE=("$1" "$2"); shift ;;
    --) shift; MAP_FLAGS=("$@"); break ;;
    *) echo "budgets.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
for budget in fixed auto; do
  rm -rf "${OUT:?}/$budget"
  mkdir -p "$OUT/$budget"
  "$BIN" map "$FOLDER" -o "$OUT/$budget" --budget "$budget" --json "${MAP_FLAGS[@]}" \
    > "$OUT/$budget/map.json"
done
/usr/bin/python3 "$ROOT/bench/compare_budgets.py" "$OUT/fixed" "$OUT/auto" "${REFERENCE[@]}"
