#!/usr/bin/env bash
# The main job on a fresh machine: install dependencies, build, generate a
# demo pair of street scans 135 degrees apart and register it with BO-ICP.
# Usage: bash deploy/demo.sh [OUTDIR]   (default: build/demo)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-build/demo}"

bash deploy/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)" --target boicp

build/bin/boicp demo-data --out "$out"
# A ground vehicle: roll and pitch within ~11 degrees, any yaw.
build/bin/boicp register --source "$out/source.xyz" --target "$out/target.xyz" \
  --config C --rotation-bounds 0.2,0.2,3.14159 --json | tee "$out/result.json"
echo "truth (T_target_source) from $out/truth.txt:" >&2
cat "$out/truth.txt" >&2
