# Sourced by the bench scripts that measure boicpd (scale.sh, throughput.sh).
#
# start_boicpd LOG [boicpd flags...]: starts "$BIN/boicpd" on a free loopback
# port with its log in LOG, sets PID to its process id (the caller stops it),
# and exports BOICP_SERVER once the daemon logs "listening on HOST:PORT".
# Exits the script, printing the log, when that line has not come in 30 s.
start_boicpd() {
  local log=$1 addr=""
  shift
  "$BIN/boicpd" --listen 127.0.0.1:0 "$@" >"$log" 2>&1 &
  PID=$!
  for _ in $(seq 1 300); do
    addr="$(grep -o 'listening on [^ ]*' "$log" | head -n 1 | cut -d' ' -f3 || true)"
    [ -n "$addr" ] && break
    sleep 0.1
  done
  [ -n "$addr" ] || { echo "boicpd did not start:" >&2; cat "$log" >&2; exit 1; }
  export BOICP_SERVER="$addr"
}
