#!/usr/bin/env bash
# The main job on a fresh machine: install dependencies, build what it runs
# (boicp, boicpd and the Python package; no tests, no benchmarks: .ci/run builds
# and runs those), install the Python package, start boicpd on a free loopback port with its
# data directory under build/, submit a logged drive with the boicp client (a generated 8-scan drive, or
# the scans of --data DIR), follow its progress, export the map, trajectory
# and preview, and stop the daemon.
# Usage: bash deploy/demo.sh [--data DIR] [--out OUTDIR] [--preset A|B|C]
#   --data DIR   a scan folder boicp submit reads (KITTI, TUM, 7-Scenes, or .pcd/.ply/.xyz files)
#   --out OUTDIR default build/demo: map.bt map.png map.ot map.ply trajectory.tum trajectory.kitti
#   --preset P   BO-ICP preset, default C
# BOICP_BUILD_DIR (default build) names the build folder.
set -euo pipefail
cd "$(dirname "$0")/.."

build="${BOICP_BUILD_DIR:-build}"
data="" out="$build/demo" preset="C"
while [ $# -gt 0 ]; do
  case "$1" in
    --data) data="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --preset) preset="$2"; shift 2 ;;
    *) echo "usage: bash deploy/demo.sh [--data DIR] [--out OUTDIR] [--preset A|B|C]" >&2; exit 2 ;;
  esac
done

bash deploy/install-deps.sh
# Unity batches, as .ci/run and the Dockerfile build: each parses the heavy
# headers once.
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DBOICP_BUILD_TESTS=OFF -DCMAKE_UNITY_BUILD=ON
cmake --build "$build" -j"$(nproc)" --target boicp_apps
boicp="$build/bin/boicp"
# The Python package, where Debian's python3 finds it: `python3 -c "import boicp"`.
if [ -f "$build/python/boicp/__init__.py" ]; then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  $sudo cmake --install "$build" --component python
fi

mkdir -p "$out"
if [ -z "$data" ]; then
  data="$out/drive"
  "$boicp" demo-data --scans 8 --out "$data"
fi

data_dir="$build/boicpd-data"
log="$out/boicpd.log"
"$build/bin/boicpd" --listen 127.0.0.1:0 --data-dir "$data_dir" --workers "$(nproc)" >"$log" 2>&1 &
pid=$!
# Whatever happens below, the daemon is drained and stopped.
trap 'kill -TERM "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true' EXIT

addr=""
for _ in $(seq 1 600); do
  addr="$(grep -o 'listening on [^ ]*' "$log" | head -n 1 | cut -d' ' -f3 || true)"
  [ -n "$addr" ] && break
  if ! kill -0 "$pid" 2>/dev/null; then
    echo "boicpd exited:" >&2; cat "$log" >&2; exit 1
  fi
  sleep 0.1
done
if [ -z "$addr" ]; then echo "boicpd did not start:" >&2; cat "$log" >&2; exit 1; fi
echo "boicpd listening on $addr (log $log, data $data_dir)"
export BOICP_SERVER="$addr"

job="$("$boicp" submit "$data" --config "$preset" --wait)"
"$boicp" show "$job"
"$boicp" export "$job" -o "$out/map.bt"  # also writes the preview map.png
for file in map.ot map.ply trajectory.tum trajectory.kitti; do
  "$boicp" export "$job" -o "$out/$file" --no-preview
done

kill -TERM "$pid"
wait "$pid"
trap - EXIT
echo "done: $out/{map.bt,map.png,map.ot,map.ply,trajectory.tum,trajectory.kitti}"
