#!/usr/bin/env bash
# Point-to-plane against point-to-point ICP in the search evaluations, at
# several seeds, in both modes (the dataset table and --auto-settings): the
# BO methods on every shared dataset with --icp-objective point, then plane,
# for each seed and mode; bench/objectives_report.py prints successes and
# median times side by side. Successes are exact (fixed seeds); the two
# objectives of one seed and mode run back to back, so their times share the
# machine's load.
#
#   bench/objectives.sh [--seeds "20230301 14 15"] [--out DIR] [--bin FILE]
#                       [--data-root DIR]
#
# Writes DIR/MODE-OBJECTIVE-SEED/ (boicp-bench output) and DIR/objectives.md
# (default /tmp/boicp-objectives).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SEEDS="20230301 14 15"
OUT=/tmp/boicp-objectives
BIN="$ROOT/build/bin/boicp-bench"
# Open3D's OpenMP threads sleep while they wait, as in bench/run.sh.
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-PASSIVE}"
DATA_ROOT="$ROOT/../shared/data"
while [ $# -gt 0 ]; do
  case "$1" in
    --seeds) SEEDS="$2"; shift ;;
    --out) OUT="$2"; shift ;;
    --bin) BIN="$2"; shift ;;
    --data-root) DATA_ROOT="$2"; shift ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "objectives.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done

PAIRS=()
for name in kitti00 7scenes_redkitchen bunny; do
  [ -f "$DATA_ROOT/$name/pairs.csv" ] && PAIRS+=("$DATA_ROOT/$name/pairs.csv")
done
if [ "${#PAIRS[@]}" -eq 0 ]; then
  echo "objectives.sh: SKIP: no pairs.csv under $DATA_ROOT (the shared real data is absent)" >&2
  exit 77
fi

mkdir -p "$OUT"
for seed in $SEEDS; do
  for mode in table auto; do
    for objective in point plane; do
      args=(--methods bo-A,bo-B,bo-C,bo-C-6dof --seed "$seed" --threads 2
            --pairs "$(IFS=,; echo "${PAIRS[*]}")" --icp-objective "$objective"
            --out "$OUT/$mode-$objective-$seed")
      [ "$mode" = auto ] && args+=(--auto-settings)
      "$BIN" "${args[@]}" > "$OUT/$mode-$objective-$seed.log" 2>&1
      echo "objectives.sh: $(date -u +%T) $mode $objective seed $seed done" >&2
    done
  done
done
/usr/bin/python3 "$ROOT/bench/objectives_report.py" "$OUT" | tee "$OUT/objectives.md"
