#!/usr/bin/env bash
# The benchmark in one command: every method on the shared real data with
# fixed seeds, then the figures and a check that every method produced rows.
#
#   bench/run.sh            standard suite into bench/results/ (< 30 min on 2 cores)
#   bench/run.sh --quick    smoke test: 1 pair per dataset, reduced budgets (< 3 min)
#   bench/run.sh --auto-settings
#                           BO methods choose their settings from the clouds (no
#                           dataset table), sources at any rotation (KITTI: any
#                           yaw) -> bench/results-auto/
#
# Options: --out DIR, --bin PATH (default build/bin/boicp-bench, built if
# missing), --data-root DIR (default ../shared/data), --threads T (default 2).
# Without the data, the standard suite is skipped (exit 77) and --quick runs
# on generated street pairs instead.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
QUICK=0
AUTO=0
OUT=""
BIN=""
DATA_ROOT="$ROOT/../shared/data"
THREADS=2
SEED=20230301  # fixed: the same perturbations and method seeds on every run
METHODS="bo-A,bo-B,bo-C,bo-C-6dof,bo-C-auto,naive,icp-identity,pyramid,ransac-fpfh,fgr"

while [ $# -gt 0 ]; do
  case "$1" in
    --quick) QUICK=1 ;;
    --auto-settings) AUTO=1 ;;
    --out) OUT="$2"; shift ;;
    --bin) BIN="$2"; shift ;;
    --data-root) DATA_ROOT="$2"; shift ;;
    --threads) THREADS="$2"; shift ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) echo "run.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done

if [ -z "$OUT" ]; then
  if [ "$QUICK" = 1 ]; then OUT="$(mktemp -d /tmp/boicp-bench-quick.XXXXXX)"
  elif [ "$AUTO" = 1 ]; then OUT="$ROOT/bench/results-auto"
  else OUT="$ROOT/bench/results"; fi
fi

PYTHON=/usr/bin/python3  # Debian's, with python3-matplotlib (deploy/install-deps.sh)
[ -x "$PYTHON" ] || PYTHON=python3

if [ -z "$BIN" ]; then
  BIN="$ROOT/build/bin/boicp-bench"
  if [ ! -x "$BIN" ]; then
    echo "run.sh: building $BIN" >&2
    cmake -S "$ROOT" -B "$ROOT/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build "$ROOT/build" -j"$THREADS" --target boicp-bench >/dev/null
  fi
fi

ARGS=(--methods "$METHODS" --seed "$SEED" --threads "$THREADS" --out "$OUT")
DATASETS=()
for name in kitti00 7scenes_redkitchen bunny; do
  [ -f "$DATA_ROOT/$name/pairs.csv" ] && DATASETS+=("$DATA_ROOT/$name/pairs.csv")
done

if [ "${#DATASETS[@]}" -eq 0 ]; then
  if [ "$QUICK" = 0 ]; then
    echo "run.sh: SKIP: no pairs.csv under $DATA_ROOT (the shared real data is absent);" \
         "the standard suite needs it. bench/run.sh --quick runs on generated pairs." >&2
    exit 77
  fi
  echo "run.sh: no real data under $DATA_ROOT: smoke test on 2 generated street pairs" >&2
  ARGS+=(--synthetic 2 --scaling synthetic)
else
  ARGS+=(--pairs "$(IFS=,; echo "${DATASETS[*]}")")
  if [ "$QUICK" = 1 ]; then
    # The bunny is the cheapest dataset to run the scaling code paths on.
    SCALING="$(basename "$(dirname "${DATASETS[-1]}")")"
    ARGS+=(--max-pairs 1 --scaling "$SCALING")
  elif [ -f "$DATA_ROOT/kitti00/pairs.csv" ]; then
    ARGS+=(--scaling kitti00)
  fi
fi
[ "$QUICK" = 1 ] && ARGS+=(--quick)
[ "$AUTO" = 1 ] && ARGS+=(--auto-settings)

mkdir -p "$OUT"
rm -f "$OUT"/results.csv "$OUT"/summary.md "$OUT"/*.png
START=$(date +%s)
# PASSIVE: threads sleep at OpenMP barriers instead of spinning (see main.cpp).
OMP_WAIT_POLICY=PASSIVE OMP_NUM_THREADS="$THREADS" "$BIN" "${ARGS[@]}"
"$PYTHON" "$ROOT/bench/plot.py" "$OUT"
"$PYTHON" "$ROOT/bench/ratios.py" "$OUT"
"$PYTHON" "$ROOT/bench/check_results.py" "$OUT" "$METHODS"
echo "run.sh: done in $(( $(date +%s) - START )) s; results in $OUT"
