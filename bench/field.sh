#!/usr/bin/env bash
# The field-data suite: the bench's pairs as they are and under each field
# condition (bench/field_conditions.hpp), automatic settings, then the
# report of success and flagged misses per condition (bench/field_report.py).
#
#   bench/field.sh OUT [--methods M[,M...]] [--data-root DIR] [--threads T] [--seed S]
#
# The seed draws each pair's start and each condition's cut, shift and
# subsample; another seed is another sample of the same suite.
# Writes OUT/<condition>/ (a boicp-bench run each, with attempts.csv for
# bench/fit_confidence.py --folds) and OUT/<condition>.log.
# Uses build/bin/boicp-bench (BIN overrides).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BIN:-$ROOT/build/bin/boicp-bench}"
# Open3D's OpenMP threads sleep while they wait, as in bench/run.sh.
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-PASSIVE}"
[ $# -ge 1 ] || { sed -n '2,13p' "$0"; exit 2; }
OUT="$1"; shift
METHODS="bo-C-auto,bo-C"
DATA_ROOT="$ROOT/../shared/data"
THREADS=2
SEED=20230301
while [ $# -gt 0 ]; do
  case "$1" in
    --methods) METHODS="$2"; shift ;;
    --data-root) DATA_ROOT="$2"; shift ;;
    --threads) THREADS="$2"; shift ;;
    --seed) SEED="$2"; shift ;;
    *) echo "field.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
mkdir -p "$OUT"
PAIRS="$DATA_ROOT/kitti00/pairs.csv,$DATA_ROOT/7scenes_redkitchen/pairs.csv,$DATA_ROOT/bunny/pairs.csv"
for condition in clean sector quarter far-returns tilt far-origin geo-origin; do
  "$BIN" --methods "$METHODS" --seed "$SEED" --threads "$THREADS" --auto-settings \
    --pairs "$PAIRS" --field "$condition" --out "$OUT/$condition" > "$OUT/$condition.log" 2>&1
done
/usr/bin/python3 "$ROOT/bench/field_report.py" "$OUT"
