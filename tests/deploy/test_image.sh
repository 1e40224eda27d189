#!/usr/bin/env bash
# Builds the container image from ./Dockerfile and runs it the ways the README
# describes:
#   - the runtime image holds no compiler and no headers (its size is printed);
#   - with the image's own settings (0.0.0.0, no token) boicpd refuses to
#     start, naming --token-file and --insecure-no-auth;
#   - the daemon container, given a bearer token, on a named volume passes its
#     HEALTHCHECK (boicp health) and runs as uid 10001;
#   - the HOST client submits a drive (../shared/data/kitti00, or a generated
#     drive when absent), exports map.bt and the trajectory, which must match
#     the reference poses;
#   - `stop` drains the daemon, which exits 0; a new container on the same
#     volume still has the job and serves the same map.bt;
#   - `boicp map` as a one-shot job in the image, scans and output mounted;
#   - the compose file brought up (podman-compose or docker compose) and the
#     same submit-and-export check; skipped, with a message, when neither exists.
# The engine is docker when `docker info` works, else podman (set up with
# ../shared/tools/podman-setup.sh when missing). Containers use host networking
# with a free loopback port, and are removed on exit, as are the volumes.
# Usage: tests/deploy/test_image.sh [--prebuilt] BIN_DIR
#   BIN_DIR      the host build's binaries (boicp is the host client), e.g. build/bin
#   --prebuilt   the image takes BIN_DIR's boicpd and boicp (--target
#                prebuilt) instead of compiling them again: for .ci/run,
#                whose host build on the same Debian release has just been tested
#   BOICP_SHARED_DIR   default ../shared beside the repository
#   BOICP_IMAGE_SKIP_COMPOSE=1  skip the compose part
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
prebuilt=""
if [ "${1:-}" = --prebuilt ]; then
  prebuilt=1
  shift
fi
if [ $# -ne 1 ] || [ ! -x "$1/boicp" ] || { [ -n "$prebuilt" ] && [ ! -x "$1/boicpd" ]; }; then
  echo "usage: $0 [--prebuilt] BIN_DIR (a folder holding the host build's boicp, and boicpd with --prebuilt)" >&2
  exit 2
fi
bin=$(cd "$1" && pwd)
shared=${BOICP_SHARED_DIR:-$root/../shared}
version=$(sed -n 's/^project(boicp VERSION \([0-9.]*\).*/\1/p' "$root/CMakeLists.txt")
image="boicp:$version"
tag="boicp-test-$$"
tmp=$(mktemp -d /tmp/boicp-image-test.XXXXXX)
# The image's user (10001) reads the mounted scans and writes the mounted output.
chmod 0755 "$tmp"
engine=""
containers=()
volumes=()
compose_up=""

log() { echo "test_image: $*"; }
fail() {
  echo "test_image: FAIL: $*" >&2
  exit 1
}

cleanup() {
  local code=$?
  set +e
  if [ -n "$compose_up" ]; then
    "${compose[@]}" down -v >"$tmp/compose-down.log" 2>&1
    # podman-compose 1.0 leaves the project's network behind.
    "$engine" network rm -f "${tag}_default" >/dev/null 2>&1
  fi
  for c in "${containers[@]}"; do
    if [ "$code" -ne 0 ]; then
      echo "--- logs of $c" >&2
      "$engine" logs "$c" 2>&1 | tail -n 30 >&2
    fi
    "$engine" rm -f "$c" >/dev/null 2>&1
  done
  for v in "${volumes[@]}"; do "$engine" volume rm -f "$v" >/dev/null 2>&1; done
  rm -rf "$tmp"
  exit "$code"
}
trap cleanup EXIT

elapsed() { echo $(($(date +%s) - $1)); }

free_port() {
  python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

# ------------------------------------------------------------------ engine

if command -v docker >/dev/null 2>&1 && docker info >/dev/null 2>&1; then
  engine=docker
else
  # podman-setup.sh also writes the runtime settings these machines need and
  # builds the debian base images; it is not needed once those exist.
  if ! command -v podman >/dev/null 2>&1 \
    || ! grep -qs 'runtime = "runc"' /etc/containers/containers.conf \
    || ! podman image exists debian:bookworm || ! podman image exists debian:bookworm-slim; then
    setup="$shared/tools/podman-setup.sh"
    [ -f "$setup" ] || fail "no working docker engine, podman not set up, and no $setup"
    log "setting up podman with $setup"
    bash "$setup" >"$tmp/podman-setup.log" 2>&1 || { cat "$tmp/podman-setup.log" >&2; fail "podman setup"; }
  fi
  engine=podman
fi
log "engine: $engine ($("$engine" --version))"

# ------------------------------------------------------------------- build

build_flags=(-t "$image" -f "$root/Dockerfile")
# podman's default OCI format drops HEALTHCHECK; the docker format keeps it.
[ "$engine" = podman ] && build_flags+=(--format docker)
context=$root
if [ -n "$prebuilt" ]; then
  # Only what the base and prebuilt stages copy: the build stage is unused and skipped.
  context=$tmp/context
  mkdir -p "$context/deploy" "$context/build/bin"
  cp "$root/deploy/install-deps.sh" "$context/deploy/"
  cp "$bin/boicpd" "$bin/boicp" "$context/build/bin/"
  build_flags+=(--target prebuilt)
fi
start=$(date +%s)
log "building $image${prebuilt:+ around the binaries of $bin} (log $tmp/build.log)"
if ! "$engine" build "${build_flags[@]}" "$context" >"$tmp/build.log" 2>&1; then
  tail -n 40 "$tmp/build.log" >&2
  fail "$engine build"
fi
build_s=$(elapsed "$start")
size=$("$engine" image inspect --format '{{.Size}}' "$image")
log "built $image in ${build_s} s; size $((size / 1000000)) MB"

# ------------------------------------------------------ runtime image content

# Anything that compiles, and any header, means build files leaked into the runtime
# stage; a library the binaries cannot load means the runtime stage misses a package.
# shellcheck disable=SC2016  # expanded by the container's shell
leaks=$("$engine" run --rm --no-healthcheck --network host --entrypoint sh "$image" -c '
  for c in cc c++ gcc g++ clang clang++ cpp ld as make cmake; do
    command -v "$c" >/dev/null 2>&1 && echo "compiler/tool: $c"
  done
  find /usr/include /usr/local/include -type f 2>/dev/null | head -n 5 | sed "s/^/header: /"
  ldd /usr/local/bin/boicpd /usr/local/bin/boicp | grep "not found" | sed "s/^/missing library: /"
  dpkg-query -W -f "\${Package}\n" | grep -E -- "-dev$|^(gcc|g\+\+|cpp|clang|llvm)(-[0-9]+)?$" | sed "s/^/package: /"
  true')
[ -z "$leaks" ] || fail "the runtime image is wrong:
$leaks"
uid=$("$engine" run --rm --no-healthcheck --network host "$image" id -u)
[ "$uid" = 10001 ] || fail "the image runs as uid $uid, want 10001"
health_cmd=$("$engine" image inspect --format '{{json .Config.Healthcheck}}' "$image")
case "$health_cmd" in
  *'"boicp","health"'* | *'"boicp", "health"'*) ;;
  *) fail "the image's HEALTHCHECK is $health_cmd, want CMD boicp health" ;;
esac
log "runtime image: no compiler, no headers, every library found, user $uid, HEALTHCHECK $health_cmd"

# ------------------------------------------------------------------ drive

kitti="$shared/data/kitti00"
if [ -d "$kitti/velodyne" ] && [ -f "$kitti/pairs.csv" ]; then
  scans="$kitti"
  map_flags=(--rotation-bounds "0.2,0.2,3.14159")  # a ground vehicle
  reference=(--pairs-csv "$kitti/pairs.csv")
  log "drive: $kitti"
else
  scans="$tmp/drive"
  "$bin/boicp" demo-data --scans 6 --out "$scans" >/dev/null
  chmod -R a+rX "$scans"
  map_flags=()
  reference=(--truth "$scans/truth.kitti")
  log "drive: $kitti absent, a generated drive of 6 scans"
fi

# ------------------------------------------------------------- the daemon

# The image is closed by default: with its own settings (0.0.0.0, no token)
# boicpd refuses to start, naming the flags that open it.
"$engine" run --rm --no-healthcheck --network none "$image" >"$tmp/open.log" 2>&1 && fail "boicpd started open"
grep -q -- '--token-file' "$tmp/open.log" && grep -q -- '--insecure-no-auth' "$tmp/open.log" \
  || { cat "$tmp/open.log" >&2; fail "the refusal does not name --token-file and --insecure-no-auth"; }
log "closed by default: $(head -n 1 "$tmp/open.log" | cut -c 1-80)..."

# Every daemon below requires this bearer token; the host client sends it
# (over loopback, so in plaintext: --insecure).
token="$tmp/token"
head -c 24 /dev/urandom | base64 >"$token"
chmod 0644 "$token"
auth=(--token-file "$token" --insecure)

# Starts the daemon container NAME on VOLUME with a free port; sets BOICP_SERVER.
start_daemon() {
  local name=$1 volume=$2 port
  port=$(free_port)
  export BOICP_SERVER="127.0.0.1:$port"
  local flags=(-d --name "$name" --network host -v "$volume:/var/lib/boicpd"
    -v "$token:/run/secrets/boicpd-token:ro" -e BOICPD_AUTH_TOKEN_FILE=/run/secrets/boicpd-token
    -e "BOICPD_LISTEN=$BOICP_SERVER" -e "BOICP_SERVER=$BOICP_SERVER" -e BOICPD_WORKERS=2)
  # docker runs the HEALTHCHECK itself, every --health-interval; podman here has no
  # systemd timers, so the test runs it with `podman healthcheck run`.
  [ "$engine" = docker ] && flags+=(--health-interval 2s)
  containers+=("$name")
  # podman reports here that it cannot add systemd timers for the healthcheck.
  "$engine" run "${flags[@]}" "$image" >/dev/null 2>"$tmp/run-$name.log" \
    || { cat "$tmp/run-$name.log" >&2; fail "$engine run $name"; }
}

# Waits until the image's HEALTHCHECK passes in container NAME.
wait_healthy() {
  local name=$1 start
  start=$(date +%s)
  while [ "$(elapsed "$start")" -lt 120 ]; do
    if [ "$("$engine" inspect --format '{{.State.Running}}' "$name")" != true ]; then
      fail "container $name exited ($("$engine" inspect --format '{{.State.ExitCode}}' "$name"))"
    fi
    if [ "$engine" = podman ]; then
      podman healthcheck run "$name" >/dev/null 2>&1 && return 0
    else
      [ "$(docker inspect --format '{{.State.Health.Status}}' "$name")" = healthy ] && return 0
    fi
    sleep 1
  done
  fail "container $name: HEALTHCHECK (boicp health) did not pass within 120 s"
}

# Submits the drive with the host client, waits, exports into DIR and checks it.
submit_and_export() {
  local dir=$1 job
  mkdir -p "$dir"
  job=$("$bin/boicp" submit "$scans" "${map_flags[@]}" "${auth[@]}" --wait 2>"$dir/submit.log") \
    || { tail -n 20 "$dir/submit.log" >&2; fail "boicp submit --wait"; }
  "$bin/boicp" export "$job" -o "$dir/map.bt" "${auth[@]}" >/dev/null
  "$bin/boicp" export "$job" -o "$dir/trajectory.kitti" "${auth[@]}" >/dev/null
  head -n 1 "$dir/map.bt" | grep -q '^# Octomap OcTree binary file' || fail "$dir/map.bt is not an OctoMap"
  python3 "$root/tests/deploy/check_trajectory.py" "$dir/trajectory.kitti" "${reference[@]}" \
    >"$dir/check.log" || { cat "$dir/check.log" >&2; fail "trajectory of job $job"; }
  tail -n 1 "$dir/check.log"
  echo "$job" >"$dir/job"
}

volume="$tag-data"
"$engine" volume create "$volume" >/dev/null
volumes+=("$volume")
start=$(date +%s)
start_daemon "$tag-a" "$volume"
wait_healthy "$tag-a"
log "daemon healthy after $(elapsed "$start") s on $BOICP_SERVER"
# shellcheck disable=SC2016  # awk's field, read in the container
daemon_uid=$("$engine" exec "$tag-a" awk '/^Uid:/ {print $2}' /proc/1/status)
[ "$daemon_uid" = 10001 ] || fail "boicpd runs as uid $daemon_uid, want 10001"

start=$(date +%s)
submit_and_export "$tmp/daemon"
job=$(cat "$tmp/daemon/job")
log "job $job: map.bt and trajectory exported in $(elapsed "$start") s"

"$engine" stop -t 60 "$tag-a" >/dev/null 2>>"$tmp/stop.log"
code=$("$engine" inspect --format '{{.State.ExitCode}}' "$tag-a")
"$engine" logs "$tag-a" >"$tmp/daemon-a.log" 2>&1
[ "$code" = 0 ] || fail "boicpd exited $code after stop"
if ! grep -q 'draining' "$tmp/daemon-a.log" || ! grep -q 'stopped' "$tmp/daemon-a.log"; then
  fail "boicpd did not log draining and stopped"
fi
log "stop: drained, exit code 0"

start_daemon "$tag-b" "$volume"
wait_healthy "$tag-b"
"$bin/boicp" show "$job" "${auth[@]}" >"$tmp/show.log" 2>&1 || { cat "$tmp/show.log" >&2; fail "job $job is gone after a restart"; }
grep -qi 'succeeded' "$tmp/show.log" || { cat "$tmp/show.log" >&2; fail "job $job is not succeeded after a restart"; }
"$bin/boicp" export "$job" -o "$tmp/restart-map.bt" "${auth[@]}" >/dev/null
cmp -s "$tmp/daemon/map.bt" "$tmp/restart-map.bt" || fail "map.bt differs after a restart"
"$engine" stop -t 60 "$tag-b" >/dev/null 2>>"$tmp/stop.log"
log "restart on the same volume: job $job still succeeded, same map.bt"

# ------------------------------------------------------- one-shot batch job

batch_out="$tmp/batch-out"
mkdir -p "$batch_out"
chmod 0777 "$batch_out"
start=$(date +%s)
"$engine" run --rm --no-healthcheck --network host -v "$scans:/scans:ro" -v "$batch_out:/out" "$image" \
  boicp map /scans -o /out --count 4 "${map_flags[@]}" >"$tmp/batch.log" 2>&1 \
  || { tail -n 20 "$tmp/batch.log" >&2; fail "boicp map in the image"; }
for f in map.bt map.ot trajectory.kitti trajectory.tum pairs.json preview.png; do
  [ -s "$batch_out/$f" ] || fail "the batch job wrote no $f"
done
owner=$(stat -c %u "$batch_out/map.bt")
[ "$engine" = docker ] || [ "$(id -u)" != 0 ] || [ "$owner" = 10001 ] \
  || fail "the batch job wrote map.bt as uid $owner, want 10001"
python3 "$root/tests/deploy/check_trajectory.py" "$batch_out/trajectory.kitti" "${reference[@]}" \
  >"$tmp/batch-check.log" || { cat "$tmp/batch-check.log" >&2; fail "batch trajectory"; }
log "one-shot boicp map in the image: $(elapsed "$start") s, $(tail -n 1 "$tmp/batch-check.log")"

# ------------------------------------------------------------------ compose

if [ "${BOICP_IMAGE_SKIP_COMPOSE:-0}" = 1 ]; then
  log "compose: skipped (BOICP_IMAGE_SKIP_COMPOSE=1)"
  exit 0
fi
compose=()
if [ "$engine" = docker ] && docker compose version >/dev/null 2>&1; then
  compose=(docker compose)
elif [ "$engine" = podman ]; then
  if ! command -v podman-compose >/dev/null 2>&1 && [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    log "installing podman-compose (apt)"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends podman-compose \
      >"$tmp/apt.log" 2>&1 || { apt-get update -q >/dev/null 2>&1 \
        && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends podman-compose \
          >"$tmp/apt.log" 2>&1; } || true
  fi
  command -v podman-compose >/dev/null 2>&1 && compose=(podman-compose)
fi
if [ "${#compose[@]}" -eq 0 ]; then
  log "compose: SKIPPED, neither docker compose nor podman-compose is available"
  exit 0
fi
compose_port=$(free_port)
export BOICP_HOST_PORT="$compose_port" BOICP_TOKEN_FILE="$token"
export BOICP_SERVER="127.0.0.1:$compose_port"
compose+=(-p "$tag" -f "$root/deploy/docker-compose.yml")
start=$(date +%s)
compose_up=1
"${compose[@]}" up -d boicpd >"$tmp/compose-up.log" 2>&1 \
  || { cat "$tmp/compose-up.log" >&2; fail "${compose[*]} up"; }
compose_container=$("$engine" ps -q --filter "label=com.docker.compose.project=$tag" | head -n 1)
[ -n "$compose_container" ] || fail "${compose[*]} up started no container"
wait_healthy "$compose_container"
submit_and_export "$tmp/compose"
log "compose (${compose[*]}): healthy, job $(cat "$tmp/compose/job") exported, $(elapsed "$start") s"
log "ok"
