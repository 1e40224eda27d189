#!/usr/bin/env bash
# Throughput and memory of the service. First the peak memory of one
# `boicp register` (config C) on a KITTI and a 7-Scenes pair. Then boicpd on a
# free loopback port registers one batch of consecutive 7-Scenes frames (100
# pairs by default, config C) with 1 and then 2 workers. The daemon's CPU
# time is sampled from /proc twice a second, so the figures say how busy it
# kept the cores while pairs were registered (and while the map was fused),
# how many pairs a minute it managed, and its peak resident memory.
#
#   bench/throughput.sh [--pairs N] [--workers "1 2"] [--out FILE] [--bin DIR]
#
# Writes Markdown tables to FILE (default bench/results/throughput.md) and
# the samples next to it (daemon_samples_w<W>.csv). Needs the
# shared data (../shared/data); exits 77 without it.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PAIRS=100
WORKERS="1 2"
OUT="$ROOT/bench/results/throughput.md"
KITTI="$ROOT/../shared/data/kitti00"
BIN="$ROOT/build/bin"
DATA="$ROOT/../shared/data/7scenes_redkitchen"
while [ $# -gt 0 ]; do
  case "$1" in
    --pairs) PAIRS="$2"; shift ;;
    --workers) WORKERS="$2"; shift ;;
    --out) OUT="$2"; shift ;;
    --bin) BIN="$2"; shift ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "throughput.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
if [ ! -d "$DATA/depth" ]; then
  echo "throughput.sh: SKIP: $DATA is absent (the shared real data)" >&2
  exit 77
fi

CLK_TCK="$(getconf CLK_TCK)"
WORK="$(mktemp -d /tmp/boicp-throughput.XXXXXX)"
# shellcheck source=bench/start_boicpd.sh
source "$(dirname "$0")/start_boicpd.sh"
PID=""
trap '[ -n "$PID" ] && kill -TERM "$PID" 2>/dev/null; wait 2>/dev/null; rm -rf "$WORK"' EXIT

cpu_seconds() {  # utime + stime of a process, in seconds
  awk -v tck="$CLK_TCK" '{ sub(/^.*\) /, ""); print ($12 + $13) / tck }' "/proc/$1/stat"
}
job_field() {  # one field of `boicp show --json`
  "$BIN/boicp" show "$1" --json | python3 -c "import json,sys; print(json.load(sys.stdin)['$2'])"
}

peak_rss_mb() {  # runs a command; prints its peak resident memory in MB
  python3 -c 'import resource, subprocess, sys
subprocess.run(sys.argv[1:], check=True, stdout=subprocess.DEVNULL)
print(f"{resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024:.0f}")' "$@"
}

mkdir -p "$(dirname "$OUT")"
{
  echo "| one registration (boicp register, config C, 1 thread) | peak RSS MB |"
  echo "|---|---:|"
  echo "| KITTI 00 scans 0 -> 1 | $(peak_rss_mb "$BIN/boicp" register -q --source "$KITTI/velodyne/000001.bin" \
    --target "$KITTI/velodyne/000000.bin" --rotation-bounds 0.2,0.2,3.14159) |"
  echo "| 7-Scenes frames 10 -> 0 | $(peak_rss_mb "$BIN/boicp" register -q \
    --source "$DATA/depth/frame-000010.depth.png" --target "$DATA/depth/frame-000000.depth.png" \
    --intrinsics-file "$DATA/camera-intrinsics.txt" --depth-scale 1000 --voxel 0.05 \
    --translation-bounds 1,1,1) |"
  echo
  echo "| workers | pairs | registration s | pairs / min | CPU busy while registering | fusion s | CPU busy while fusing | peak RSS MB |"
  echo "|---:|---:|---:|---:|---:|---:|---:|---:|"
} >"$OUT.tmp"

for workers in $WORKERS; do
  log="$WORK/boicpd_w$workers.log"
  start_boicpd "$log" --data-dir "$WORK/data_w$workers" --workers "$workers" \
    --registration-threads 1

  job="$("$BIN/boicp" submit "$DATA" --count $((PAIRS + 1)) --config C --label throughput)"
  # One long-lived client follows the job and prints a line at every stage
  # change: starting `boicp show` for every sample cost about 0.09 s of CPU
  # a second, 5 % of the two cores being measured.
  watch_log="$WORK/watch_w$workers.log"
  "$BIN/boicp" watch "$job" >"$watch_log" 2>&1 &
  WATCH_PID=$!
  samples="$(dirname "$OUT")/daemon_samples_w$workers.csv"
  echo "seconds,cpu_seconds,stage" >"$samples"
  start_ms="$(($(date +%s%N) / 1000000))"
  while :; do
    elapsed_ms="$(($(date +%s%N) / 1000000 - start_ms))"
    stage="$(grep -o '^\[[a-z]*\]' "$watch_log" | tail -n 1 | tr -d '[]' || true)"
    echo "$((elapsed_ms / 1000)).$(printf '%03d' $((elapsed_ms % 1000))),$(cpu_seconds "$PID"),${stage:-queued}" >>"$samples"
    kill -0 "$WATCH_PID" 2>/dev/null || break
    sleep 0.5
  done
  wait "$WATCH_PID" || true
  state="$(job_field "$job" state)"
  [ "${state,,}" = succeeded ] || { echo "job ended $state:" >&2; tail -20 "$log" >&2; exit 1; }
  peak_kb="$(awk '/VmHWM/ {print $2}' "/proc/$PID/status")"
  kill -TERM "$PID"
  wait "$PID" || true
  PID=""
  python3 - "$samples" "$workers" "$PAIRS" "$peak_kb" >>"$OUT.tmp" <<'PY'
import csv, sys
path, workers, pairs, peak_kb = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
rows = [(float(r["seconds"]), float(r["cpu_seconds"]), r["stage"]) for r in csv.DictReader(open(path))]
# Registration ends at the first sample that sees a later stage (chaining, fusing, ...).
done = next(r for r in rows if r[2] not in ("queued", "registering"))
end = rows[-1]
t0, c0 = rows[0][0], rows[0][1]
reg_s, reg_cpu = done[0] - t0, done[1] - c0
fuse_s, fuse_cpu = end[0] - done[0], end[1] - done[1]
busy = lambda cpu, s: 100.0 * cpu / (s * workers) if s > 0 else float("nan")
print(f"| {workers} | {pairs} | {reg_s:.0f} | {60.0 * pairs / reg_s:.1f} | {busy(reg_cpu, reg_s):.0f}% of {workers} | "
      f"{fuse_s:.0f} | {busy(fuse_cpu, fuse_s):.0f}% of {workers} | {peak_kb / 1024:.0f} |")
PY
done
mv "$OUT.tmp" "$OUT"
cat "$OUT"
