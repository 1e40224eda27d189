#!/usr/bin/env bash
# How boicp scales with the length of a drive. Generated drives of
# each length (boicp demo-data --scans N) go through the one-process
# `boicp map` and through the daemon (boicpd on a free loopback port, a fresh
# one per drive, then boicp submit / watch / export). For each run it records
# the wall time of every stage (from timestamped progress lines), registered
# pairs per minute, fused scans per second, the peak resident memory of
# `boicp map` and of boicpd, and the sizes of map.bt and map.ot; then
# bench/scale_report.py prints the table, the exponent of wall time against
# scans (a log-log fit) and, when matplotlib is installed, a figure.
#
#   bench/scale.sh [--scans "100 300 1000"] [--daemon-scans "100 300 1000"]
#                  [--config A] [--budget "FLAGS"] [--threads 2] [--seed 7]
#                  [--out DIR] [--bin DIR]
#
# --budget (default "--random-samples 4 --iterations 4 --no-retry") shrinks
# the search below preset A so that 1000 pairs fit in minutes: this measures
# how the service scales, not registration accuracy.
# --threads is `boicp map --threads` and boicpd's --workers (registration
# threads 1), so both sides use the same cores. Writes DIR/runs.csv and
# DIR/scale.md (default bench/results/scale).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SCANS="100 300 1000"
DAEMON_SCANS=""
CONFIG=A
BUDGET="--random-samples 4 --iterations 4 --no-retry"
THREADS=2
SEED=7
OUT="$ROOT/bench/results/scale"
BIN="$ROOT/build/bin"
while [ $# -gt 0 ]; do
  case "$1" in
    --scans) SCANS="$2"; shift ;;
    --daemon-scans) DAEMON_SCANS="$2"; shift ;;
    --config) CONFIG="$2"; shift ;;
    --budget) BUDGET="$2"; shift ;;
    --threads) THREADS="$2"; shift ;;
    --seed) SEED="$2"; shift ;;
    --out) OUT="$2"; shift ;;
    --bin) BIN="$2"; shift ;;
    -h|--help) sed -n '2,23p' "$0"; exit 0 ;;
    *) echo "scale.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
DAEMON_SCANS="${DAEMON_SCANS:-$SCANS}"
read -r -a BUDGET_FLAGS <<<"$BUDGET"
for tool in boicp boicpd; do
  [ -x "$BIN/$tool" ] || { echo "scale.sh: $BIN/$tool is missing; build it first" >&2; exit 2; }
done

WORK="$(mktemp -d /tmp/boicp-scale.XXXXXX)"
# shellcheck source=bench/start_boicpd.sh
source "$(dirname "$0")/start_boicpd.sh"
PID=""
trap '[ -n "$PID" ] && kill -TERM "$PID" 2>/dev/null; wait 2>/dev/null; rm -rf "$WORK"' EXIT
mkdir -p "$OUT"
RUNS="$OUT/runs.csv"
[ -f "$RUNS" ] || echo "mode,scans,pairs,wall_s,upload_s,register_s,fuse_s,other_s,peak_rss_mb,bt_bytes,ot_bytes" >"$RUNS"

# Runs a command with each stderr line prefixed by the seconds since it
# started, into LOG; prints the command's peak resident memory in MB.
run_timed() {
  local log=$1; shift
  python3 - "$log" "$@" <<'PY'
import resource, subprocess, sys, time
log, cmd = sys.argv[1], sys.argv[2:]
start = time.monotonic()
with open(log, "w") as out:
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    for line in proc.stderr:
        out.write(f"{time.monotonic() - start:.3f} {line}")
    out.write(f"{time.monotonic() - start:.3f} exit {proc.wait()}\n")
if proc.returncode != 0:
    sys.exit(f"{cmd[0]} failed with {proc.returncode}; see {log}")
print(f"{resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024:.0f}")
PY
}

# Seconds (the log's first field) of the first line matching REGEX.
first_time() { grep -E -m 1 -- "$2" "$1" | cut -d' ' -f1; }
last_time() { tail -n 1 "$1" | cut -d' ' -f1; }

generate() {  # the drive of N scans, once
  local n=$1 dir="$WORK/drive_$1"
  [ -d "$dir" ] || "$BIN/boicp" demo-data --scans "$n" --seed "$SEED" --out "$dir" 2>/dev/null
  echo "$dir"
}

map_run() {
  local n=$1 drive out log rss
  drive="$(generate "$n")"
  out="$WORK/map_$n"
  log="$OUT/map_$n.log"
  rss="$(run_timed "$log" "$BIN/boicp" map "$drive" -o "$out" --config "$CONFIG" \
    "${BUDGET_FLAGS[@]}" --threads "$THREADS" --seed "$SEED")"
  local registered fused end
  registered="$(first_time "$log" ' pairs \(.*registered')"
  fused="$(first_time "$log" '^[0-9.]+ fused ')"
  end="$(last_time "$log")"
  python3 -c "r, f, e = $registered, $fused, $end
print(f'map,$n,$((n - 1)),{e:.1f},0,{r:.1f},{f - r:.1f},{e - f:.1f},$rss,' +
      f'$(stat -c %s "$out/map.bt"),$(stat -c %s "$out/map.ot")')" >>"$RUNS"
  rm -rf "$out"
}

daemon_run() {
  local n=$1 drive data log job watch_log
  drive="$(generate "$n")"
  data="$WORK/boicpd_$n"
  log="$OUT/boicpd_$n.log"
  start_boicpd "$log" --data-dir "$data" --workers "$THREADS" --registration-threads 1
  watch_log="$OUT/watch_$n.log"
  # The upload (submit) is part of what a user waits for: its own column.
  local start_ns=$(date +%s%N)
  job="$("$BIN/boicp" submit "$drive" --config "$CONFIG" "${BUDGET_FLAGS[@]}" \
    --seed "$SEED" 2>/dev/null)"
  local upload_s
  upload_s="$(python3 -c "print(($(date +%s%N) - $start_ns) / 1e9)")"
  run_timed "$watch_log" "$BIN/boicp" watch "$job" >/dev/null
  local peak_kb
  peak_kb="$(awk '/VmHWM/ {print $2}' "/proc/$PID/status")"
  "$BIN/boicp" export "$job" -o "$WORK/map_$n.bt" --no-preview >/dev/null
  "$BIN/boicp" export "$job" -o "$WORK/map_$n.ot" --no-preview >/dev/null
  kill -TERM "$PID"
  wait "$PID" || true
  PID=""
  # Registration ends when the watch first reports a later stage; fusion
  # time is the daemon's own figure.
  local registered fuse end
  registered="$(first_time "$watch_log" '\[(chaining|optimising|fusing|writing)')"
  fuse="$(grep -o 'fused [0-9]* scans in [0-9.]* s' "$log" | awk '{print $5}')"
  end="$(last_time "$watch_log")"
  python3 -c "u, r, f, e = $upload_s, $registered, $fuse, $end
print(f'daemon,$n,$((n - 1)),{u + e:.1f},{u:.1f},{r:.1f},{f:.1f},{e - r - f:.1f},' +
      f'{$peak_kb / 1024:.0f},$(stat -c %s "$WORK/map_$n.bt"),$(stat -c %s "$WORK/map_$n.ot")')" >>"$RUNS"
  rm -rf "$data" "$WORK/map_$n.bt" "$WORK/map_$n.ot"
}

for n in $SCANS; do
  echo "boicp map: $n scans" >&2
  map_run "$n"
done
for n in $DAEMON_SCANS; do
  echo "boicpd: $n scans" >&2
  daemon_run "$n"
done
python3 "$ROOT/bench/scale_report.py" "$RUNS" --threads "$THREADS" --config "$CONFIG $BUDGET" \
  --png "$OUT/scale.png" | tee "$OUT/scale.md"
