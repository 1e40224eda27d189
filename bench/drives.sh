#!/usr/bin/env bash
# The drive bench: every real sequence of the shared data with
# reference poses, mapped by `boicp map` (defaults) at strides 1, 2, 5 and
# 10, every pair scored against the sequence's own poses polished by one ICP
# (bench/drives_report.py) and the trajectory by `boicp eval` -> OUT/drives.md.
# Usage: bench/drives.sh OUT [--bin DIR] [--data-root DIR] [--strides N[,N...]] [--vlp16]
#   sequences: 7scenes_redkitchen (its pose/ files) and kitti00 (poses.txt
#   with calib.txt); with --vlp16 also vlp16_loop, scored by its revisits.csv
#   only (no per-scan poses; stride 1 takes about 15 minutes on 2 cores).
# A stride is every N-th scan of the folder as listed (7-Scenes: frames 0-99,
# then every 5th to 495); its folder of links is OUT/<sequence>/stride<N>/scans.
# Per run, under OUT/<sequence>/stride<N>/: map/ (what `boicp map` wrote:
# pairs.json, run.json, trajectory.kitti, ...), map.json (its --json summary),
# map.log, eval.json (`boicp eval --json`), eval.log and meta.json.
# A stride leaving fewer than 2 scans is a "-" row. Exits 77 without the
# shared data, 1 when a map or its eval failed (its row says so).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
usage="usage: bench/drives.sh OUT [--bin DIR] [--data-root DIR] [--strides N[,N...]] [--vlp16]"
# Open3D's OpenMP threads sleep while they wait, as in bench/run.sh.
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-PASSIVE}"

out="" bin="$ROOT/build/bin" data="$ROOT/../shared/data" strides="1,2,5,10" vlp16=0
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="${2:?$usage}"; shift 2 ;;
    --data-root) data="${2:?$usage}"; shift 2 ;;
    --strides) strides="${2:?$usage}"; shift 2 ;;
    --vlp16) vlp16=1; shift ;;
    -h|--help) echo "$usage"; exit 0 ;;
    -*) echo "$usage" >&2; exit 2 ;;
    *) [ -z "$out" ] || { echo "$usage" >&2; exit 2; }; out="$1"; shift ;;
  esac
done
[ -n "$out" ] || { echo "$usage" >&2; exit 2; }
[[ "$strides" =~ ^[1-9][0-9]*(,[1-9][0-9]*)*$ ]] || {
  echo "bench/drives.sh: --strides wants positive integers separated by commas" >&2; exit 2; }

sequences=()
[ -d "$data/7scenes_redkitchen/depth" ] && sequences+=(7scenes_redkitchen)
[ -d "$data/kitti00/velodyne" ] && sequences+=(kitti00)
[ "$vlp16" = 1 ] && [ -d "$data/vlp16_loop/pcd" ] && sequences+=(vlp16_loop)
if [ ${#sequences[@]} -eq 0 ]; then
  echo "bench/drives.sh: no shared sequences (7scenes_redkitchen, kitti00) under $data; nothing to measure" >&2
  exit 77
fi
boicp="$bin/boicp"
[ -x "$boicp" ] || { echo "bench/drives.sh: $boicp: not found; build it or give --bin DIR" >&2; exit 2; }
data="$(realpath "$data")"
mkdir -p "$out"
out="$(realpath "$out")"

# The scans of one sequence, sorted, one name a line (no directory).
list_scans() {
  case "$1" in
    7scenes_redkitchen) find "$data/$1/depth" -maxdepth 1 -name 'frame-*.depth.png' -printf '%f\n' | sort ;;
    kitti00) find "$data/$1/velodyne" -maxdepth 1 -name '*.bin' -printf '%f\n' | sort ;;
    vlp16_loop) find "$data/$1/pcd" -maxdepth 1 -name '*.pcd' -printf '%f\n' | sort ;;
  esac
}

# Builds the folder of every stride-th scan (links; KITTI's poses.txt and
# times.txt cut to the kept lines) and prints how many scans it holds.
make_subset() {
  local name="$1" stride="$2" dest="$3" src="$data/$1" kept=0 index=0 scan
  rm -rf "$dest"
  case "$name" in
    7scenes_redkitchen)
      mkdir -p "$dest/depth" "$dest/pose"
      ln -s "$src/camera-intrinsics.txt" "$dest/camera-intrinsics.txt" ;;
    kitti00)
      mkdir -p "$dest/velodyne"
      ln -s "$src/calib.txt" "$dest/calib.txt"
      : >"$dest/poses.txt"
      [ ! -f "$src/times.txt" ] || : >"$dest/times.txt" ;;
    vlp16_loop) mkdir -p "$dest" ;;
  esac
  while IFS= read -r scan; do
    if [ $((index % stride)) -eq 0 ]; then
      case "$name" in
        7scenes_redkitchen)
          ln -s "$src/depth/$scan" "$dest/depth/$scan"
          ln -s "$src/pose/${scan%.depth.png}.pose.txt" "$dest/pose/" ;;
        kitti00)
          ln -s "$src/velodyne/$scan" "$dest/velodyne/$scan"
          sed -n "$((index + 1))p" "$src/poses.txt" >>"$dest/poses.txt"
          [ ! -f "$src/times.txt" ] || sed -n "$((index + 1))p" "$src/times.txt" >>"$dest/times.txt" ;;
        vlp16_loop) ln -s "$src/pcd/$scan" "$dest/$scan" ;;
      esac
      kept=$((kept + 1))
    fi
    index=$((index + 1))
  done < <(list_scans "$name")
  echo "$kept"
}

failed=0
started=$(date +%s)
for name in "${sequences[@]}"; do
  reference="$data/$name"
  [ "$name" != vlp16_loop ] || reference="$data/vlp16_loop/revisits.csv"
  for stride in ${strides//,/ }; do
    run="$out/$name/stride$stride"
    mkdir -p "$run"
    rm -rf "$run/map" "$run/map.json" "$run/map.log" "$run/eval.json" "$run/eval.log"
    scans=$(make_subset "$name" "$stride" "$run/scans")
    status=skipped seconds=0
    if [ "$scans" -ge 2 ]; then
      echo "drives: $name stride $stride, $scans scans ..." >&2
      t0=$(date +%s.%N)
      if "$boicp" map "$run/scans" -o "$run/map" --json >"$run/map.json" 2>"$run/map.log"; then
        status=mapped
      else
        status=failed failed=1
        echo "drives: map failed, see $run/map.log" >&2
      fi
      seconds=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
      if [ "$status" = mapped ] &&
        ! "$boicp" eval "$run/map" --reference "$reference" --json >"$run/eval.json" 2>"$run/eval.log"; then
        rm -f "$run/eval.json"
        failed=1
        echo "drives: eval failed, see $run/eval.log" >&2
      fi
    fi
    printf '{"sequence": "%s", "stride": %d, "scans": %d, "status": "%s", "map_seconds": %s, "reference": "%s"}\n' \
      "$name" "$stride" "$scans" "$status" "$seconds" "$reference" >"$run/meta.json"
  done
done

/usr/bin/python3 "$ROOT/bench/drives_report.py" "$out" --boicp "$boicp" --strides "$strides" >"$out/drives.md"
cat "$out/drives.md"
echo "drives: $(( $(date +%s) - started )) s; wrote $out/drives.md" >&2
exit "$failed"
