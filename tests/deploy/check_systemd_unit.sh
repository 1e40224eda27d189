#!/usr/bin/env bash
# Verifies deploy/systemd/boicpd.service offline with systemd-analyze: it must
# parse without a single warning (verify exits 0 even on unknown keys, so any
# output fails) and its hardening must score at most 2.5 on `security`.
# Usage: check_systemd_unit.sh UNIT BOICPD   (exit 77: systemd-analyze missing)
set -euo pipefail
unit="$1" boicpd="$2"
command -v systemd-analyze >/dev/null || { echo "systemd-analyze not installed"; exit 77; }

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
# The unit runs /usr/local/bin/boicpd; verify checks that the binary exists,
# so point it at the one just built.
sed "s#^ExecStart=/usr/local/bin/boicpd#ExecStart=$boicpd#" "$unit" >"$tmp/boicpd.service"
if ! grep -q "^ExecStart=$boicpd\$" "$tmp/boicpd.service"; then
  echo "no ExecStart=/usr/local/bin/boicpd in $unit"
  exit 1
fi

if ! out="$(systemd-analyze verify "$tmp/boicpd.service" 2>&1)" || [ -n "$out" ]; then
  echo "systemd-analyze verify $unit:"; echo "$out"; exit 1
fi
# --threshold counts tenths: 25 is an exposure of 2.5 out of 10.
if ! out="$(systemd-analyze security --offline=yes --threshold=25 --no-pager \
  "$tmp/boicpd.service" 2>&1)"; then
  echo "$out" | tail -n 5; echo "$unit: hardening exposure above 2.5"; exit 1
fi
echo "$(echo "$out" | tail -n 1)"
