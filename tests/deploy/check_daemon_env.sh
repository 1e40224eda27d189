#!/usr/bin/env bash
# Runs boicpd configured only through BOICPD_* variables, as the image, the
# compose file, the Kubernetes Deployment and the systemd unit configure it.
# Usage: check_daemon_env.sh env BOICPD BOICP
#          bad values refused in one line, variables applied, a flag beats its
#          variable, SIGTERM drains and exits 0
#        check_daemon_env.sh health BOICPD BOICP
#          the image's HEALTHCHECK: `boicp health` with only BOICP_SERVER set
#          is 0 against the daemon and non-zero against a closed port
#          (exit 77 while boicp has no health subcommand)
set -euo pipefail
mode="$1" boicpd="$2" boicp="$3"
tmp="$(mktemp -d)"
pid=""
cleanup() {
  if [ -n "$pid" ]; then kill -KILL "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true; fi
  rm -rf "$tmp"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  if [ -f "$tmp/log" ]; then cat "$tmp/log"; fi
  exit 1
}

# Starts boicpd in the background with the given extra flags; sets pid and addr.
start_daemon() {
  BOICPD_LISTEN=127.0.0.1:0 BOICPD_DATA_DIR="$tmp/data" BOICPD_WORKERS=1 BOICPD_JOBS=2 \
    "$boicpd" "$@" >"$tmp/log" 2>&1 &
  pid=$!
  addr=""
  for _ in $(seq 1 600); do
    addr="$(grep -o 'listening on [^ ]*' "$tmp/log" | head -n 1 | cut -d' ' -f3 || true)"
    [ -n "$addr" ] && return 0
    kill -0 "$pid" 2>/dev/null || fail "boicpd exited before listening"
    sleep 0.1
  done
  fail "boicpd did not log 'listening on' within 60 s"
}

stop_daemon() {
  kill -TERM "$pid"
  local rc=0
  wait "$pid" || rc=$?
  pid=""
  [ "$rc" -eq 0 ] || fail "boicpd exited $rc after SIGTERM, want 0"
}

check_env() {
  local rc=0
  BOICPD_DATA_DIR="$tmp/bad-data" BOICPD_WORKERS=0 "$boicpd" >"$tmp/bad" 2>&1 || rc=$?
  [ "$rc" -eq 2 ] || fail "BOICPD_WORKERS=0: exit $rc, want 2"
  [ "$(grep -c . "$tmp/bad")" -eq 1 ] ||
    fail "BOICPD_WORKERS=0: want one line, got: $(cat "$tmp/bad")"
  grep -q -- "--workers" "$tmp/bad" || fail "BOICPD_WORKERS=0: message does not name --workers"

  rc=0
  env -u BOICPD_DATA_DIR "$boicpd" >"$tmp/bad" 2>&1 || rc=$?
  [ "$rc" -eq 2 ] || fail "no data dir at all: exit $rc, want 2"

  start_daemon --jobs 3
  grep -q "1 workers x 1 registration threads, 3 concurrent jobs, data in $tmp/data" "$tmp/log" ||
    fail "BOICPD_WORKERS=1 with --jobs 3 over BOICPD_JOBS=2 not applied"
  [ -f "$tmp/data/boicpd.sqlite" ] || fail "BOICPD_DATA_DIR not used: no $tmp/data/boicpd.sqlite"
  stop_daemon
  grep -q "received SIGTERM" "$tmp/log" || fail "no 'received SIGTERM' in the log"
  echo "env: ok"
}

check_health() {
  if ! "$boicp" --help | grep -Eq '^ +health +'; then
    echo "boicp has no health subcommand yet"
    exit 77
  fi
  start_daemon
  BOICP_SERVER="$addr" "$boicp" health >"$tmp/health" 2>&1 ||
    fail "BOICP_SERVER=$addr boicp health failed: $(cat "$tmp/health")"
  stop_daemon
  # The daemon is gone: the same probe must now fail.
  if BOICP_SERVER="$addr" timeout 30 "$boicp" health >"$tmp/health" 2>&1; then
    fail "boicp health succeeded against a stopped daemon"
  fi
  echo "health: ok"
}

case "$mode" in
  env) check_env ;;
  health) check_health ;;
  *) echo "usage: check_daemon_env.sh env|health BOICPD BOICP" >&2; exit 2 ;;
esac
