#!/usr/bin/env bash
# Installs every Debian bookworm package boicp needs to build, test and benchmark.
# Idempotent: apt-get skips what is already installed. Run as root (or via sudo).
# Usage: install-deps.sh            install the build/test packages (what CI runs)
#        install-deps.sh --list     print the build/test packages
#        install-deps.sh --runtime  install only what boicpd and boicp load at run time
#        install-deps.sh --list-runtime  print those runtime packages
# tests/deploy checks that the Dockerfile installs nothing else and that the
# runtime list matches the libraries the built binaries link.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config git ca-certificates
  libopen3d-dev libeigen3-dev liboctomap-dev
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler libssl-dev openssl
  libspdlog-dev libfmt-dev libnlopt-cxx-dev libsqlite3-dev libsqlitecpp-dev libtbb-dev
  libnanoflann-dev libcli11-dev nlohmann-json3-dev libpng-dev zlib1g-dev
  librosbag-storage-dev libzstd-dev liblz4-dev libceres-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-matplotlib python3-numpy
  python3-dev pybind11-dev python3-pytest python3-grpcio python3-protobuf
  clang-format yamllint systemd clang libclang-rt-14-dev ccache
)

# The shared libraries boicpd and boicp link directly (objdump -p NEEDED, then
# dpkg -S); apt pulls in their own dependencies.
RUNTIME_PACKAGES=(
  libc6 libgcc-s1 libstdc++6
  libopen3d0.16 liboctomap1.9 libnlopt0 libfmt9 libspdlog1.10 libsqlite3-0 libssl3
  libgrpc++1.51 libgrpc29 libprotobuf32 libabsl20220623 libtbb12
  libbz2-1.0 liblz4-1 libzstd1 zlib1g libceres3 libgoogle-glog0v6
)

case "${1:-}" in
  "") ;;
  --list) printf '%s\n' "${PACKAGES[@]}"; exit 0 ;;
  --list-runtime) printf '%s\n' "${RUNTIME_PACKAGES[@]}"; exit 0 ;;
  --runtime) PACKAGES=("${RUNTIME_PACKAGES[@]}") ;;
  *) echo "usage: install-deps.sh [--list | --runtime | --list-runtime]" >&2; exit 2 ;;
esac

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
$SUDO apt-get install -y --no-install-recommends "${missing[@]}"
