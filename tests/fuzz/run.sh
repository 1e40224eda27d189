#!/usr/bin/env bash
# Runs every libFuzzer harness for a fixed time, one after another, on a
# scratch corpus seeded from tests/fuzz/corpus/<name>/ (the repository's
# corpus is only read). Writes BUILD/fuzz-logs/<name>.log, crash artifacts in
# BUILD/fuzz-logs/artifacts/, and one summary line per harness to
# BUILD/fuzz-logs/summary.txt. Exits 1 when a harness found a problem.
#
# Usage: tests/fuzz/run.sh [--seconds N] [--build DIR] [--only NAME]...
#   --seconds N  time per harness (default 600)
#   --build DIR  a build configured with -DBOICP_BUILD_FUZZERS=ON (default build-fuzz)
#   --only NAME  run just this harness (repeatable), e.g. --only fuzz_ply
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
seconds=600
build="$root/build-fuzz"
only=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --build) build="$(cd "$2" && pwd)"; shift 2 ;;
    --only) only+=("$2"); shift 2 ;;
    *) echo "usage: run.sh [--seconds N] [--build DIR] [--only NAME]..." >&2; exit 2 ;;
  esac
done
case "$seconds" in '' | *[!0-9]*) echo "run.sh: --seconds needs a whole number" >&2; exit 2 ;; esac

names=(fuzz_kitti fuzz_pcd fuzz_ply fuzz_xyz fuzz_depth_png fuzz_ros1_bag fuzz_ros2_db3 fuzz_mcap
  fuzz_ros_messages fuzz_request)
if [ ${#only[@]} -gt 0 ]; then names=("${only[@]}"); fi

logs="$build/fuzz-logs"
mkdir -p "$logs/artifacts"
status=0
for name in "${names[@]}"; do
  binary="$build/bin/$name"
  if [ ! -x "$binary" ]; then
    echo "run.sh: $binary not built (cmake --build $build --target $name)" >&2
    exit 2
  fi
  work="$build/fuzz-work/$name"
  mkdir -p "$work"
  log="$logs/$name.log"
  start=$(date +%s)
  rc=0
  # -close_fd_mask=3 silences Open3D and protobuf warnings; libFuzzer keeps its own report.
  "$binary" -max_total_time="$seconds" -rss_limit_mb=2048 -print_final_stats=1 -close_fd_mask=3 \
    -artifact_prefix="$logs/artifacts/$name-" "$work" "$here/corpus/$name" >"$log" 2>&1 || rc=$?
  minutes=$(awk -v s=$(($(date +%s) - start)) 'BEGIN { printf "%.1f", s / 60 }')
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  line="$(date -u +%FT%TZ) $name minutes=$minutes executions=${execs:-?} exit=$rc corpus=$(ls "$work" | wc -l)"
  if [ "$rc" -ne 0 ]; then
    status=1
    line="$line FOUND: $(grep -m1 -E '^(==[0-9]+==ERROR|SUMMARY|.*runtime error)' "$log" || echo 'see log')"
  fi
  echo "$line" | tee -a "$logs/summary.txt"
done
exit $status
