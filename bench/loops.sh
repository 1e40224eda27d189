#!/usr/bin/env bash
# Loop closure on whole drives, side by side in one run: each drive mapped
# with --loops off and with the default --loops auto, both scored by
# `boicp eval` against the drive's reference -> OUT/loops.md.
# Usage: bench/loops.sh OUT [--bin DIR] [--data-root DIR] [--vlp16] [--drift]
#   drives: 7-Scenes redkitchen frames 0-495 every 5th (KinectFusion poses),
#   a generated 300-scan drive out and back (its truth.kitti), with --vlp16
#   the VLP-16 drive (its revisits.csv; 40-70 minutes on 2 cores), and with
#   --drift a generated 1000-scan drive out and back logged as a throttled
#   LiDAR log is (demo-data --drift).
set -euo pipefail
cd "$(dirname "$0")/.."

out="" bin="build/bin" data="../shared/data" vlp16=0 drift=0
usage="usage: bench/loops.sh OUT [--bin DIR] [--data-root DIR] [--vlp16] [--drift]"
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --data-root) data="$2"; shift 2 ;;
    --vlp16) vlp16=1; shift ;;
    --drift) drift=1; shift ;;
    -*) echo "$usage" >&2; exit 2 ;;
    *) out="$1"; shift ;;
  esac
done
[ -n "$out" ] || { echo "$usage" >&2; exit 2; }
if [ ! -d "$data/7scenes_redkitchen" ]; then
  echo "bench/loops.sh: no shared data at $data; nothing to measure" >&2
  exit 77
fi
boicp="$bin/boicp"
mkdir -p "$out"

# 7-Scenes every 5th frame: links, so the shared data is never copied.
kitchen="$out/drives/7scenes_every_5th"
mkdir -p "$kitchen/depth" "$kitchen/pose"
cp "$data/7scenes_redkitchen/camera-intrinsics.txt" "$kitchen/"
for frame in $(seq 0 5 495); do
  name=$(printf "frame-%06d" "$frame")
  ln -sf "$(realpath "$data/7scenes_redkitchen/depth/$name.depth.png")" "$kitchen/depth/"
  ln -sf "$(realpath "$data/7scenes_redkitchen/pose/$name.pose.txt")" "$kitchen/pose/"
done
generated="$out/drives/generated_300_loop"
[ -f "$generated/truth.kitti" ] || "$boicp" demo-data --scans 300 --loop -o "$generated" >/dev/null

drives=("7scenes_every_5th|$kitchen|$kitchen" "generated_300_loop|$generated|$generated/truth.kitti")
if [ "$drift" = 1 ]; then
  drifting="$out/drives/generated_1000_drift"
  [ -f "$drifting/truth.kitti" ] ||
    "$boicp" demo-data --scans 1000 --loop --drift -o "$drifting" >/dev/null
  drives+=("generated_1000_drift|$drifting|$drifting/truth.kitti")
fi
if [ "$vlp16" = 1 ]; then
  drives+=("vlp16_loop|$data/vlp16_loop/pcd|$data/vlp16_loop/revisits.csv")
fi

report="$out/loops.md"
{
  echo "| drive | scans | off | auto | auto / off | loops closed / candidates | loop seconds / other pairs' | wrong loops in graph | peak MB (auto) |"
  echo "|---|---|---|---|---|---|---|---|---|"
} >"$report"
for entry in "${drives[@]}"; do
  IFS='|' read -r name folder reference <<<"$entry"
  mkdir -p "$out/$name"
  for loops in off auto; do
    run="$out/$name/$loops"
    /usr/bin/time -v "$boicp" map "$folder" -o "$run" --loops "$loops" --json \
      >"$run.json" 2>"$run.log" || { echo "map failed: $run.log" >&2; exit 1; }
    "$boicp" eval "$run" --reference "$reference" --json >"$run.eval.json"
  done
  python3 - "$out/$name" "$name" >>"$report" <<'PY'
import json, sys
base, name = sys.argv[1], sys.argv[2]
off, auto = (json.load(open(f"{base}/{k}.eval.json")) for k in ("off", "auto"))
summary = json.load(open(f"{base}/auto.json"))
def ate(e):
    return e["trajectory"]["ate_rmse_m"] if "trajectory" in e else None
def revisits(e):
    rows = e.get("revisits", [])
    return sum(r["translation_error_m"] <= 0.3 and r["yaw_error_deg"] <= 2 for r in rows), len(rows)
wrong = auto.get("pair_errors", {}).get("by_kind", {}).get("loop", {}).get("wrong_in_graph", "-")
if "trajectory" in off:
    a, b = ate(off), ate(auto)
    cells = [f"ATE {a:.4f} m", f"ATE {b:.4f} m", f"{b / a:.2f}"]
else:
    (ok_off, n), (ok_auto, _) = revisits(off), revisits(auto)
    cells = [f"revisits {ok_off}/{n}", f"revisits {ok_auto}/{n}", "-"]
share = summary["loop_runtime_s"] / summary["other_pairs_runtime_s"] if summary["other_pairs_runtime_s"] else 0
peak = next((int(l.split(":")[1]) // 1024 for l in open(f"{base}/auto.log")
             if "Maximum resident set size" in l), 0)
print(f"| {name} | {summary['scans']} | " + " | ".join(cells) +
      f" | {summary['loops_closed']} / {summary['loop_candidates']} | "
      f"{summary['loop_runtime_s']:.0f} / {summary['other_pairs_runtime_s']:.0f} s ({100 * share:.0f} %)"
      f" | {wrong} | {peak} |")
PY
done
cat "$report"
