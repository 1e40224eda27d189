#!/usr/bin/env bash
# Runs deploy/slurm/submit.sh on a one-node Slurm cluster
# (../shared/tools/slurm-local.sh, stopped on exit whatever happens):
#   1. 3 shards on the KITTI folder (a generated drive when absent), then the
#      merge: its trajectory.kitti equals one `boicp map` run byte for byte;
#   2. again on a new OUTDIR, shard task 2 cancelled after its first pair, the
#      merge then cancelled by Slurm; submitting again with the same arguments
#      registers only the cancelled task's missing pairs (the pair files already
#      written stay untouched) and the merged trajectory is again the same.
# Usage: tests/deploy/test_slurm.sh BIN_DIR   (the boicp to put first on PATH)
#   BOICP_SHARED_DIR   default ../shared beside the repository
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
if [ $# -ne 1 ] || [ ! -x "$1/boicp" ]; then
  echo "usage: $0 BIN_DIR (a folder holding boicp)" >&2
  exit 2
fi
bin=$(cd "$1" && pwd)
shared=${BOICP_SHARED_DIR:-$root/../shared}
slurm_local="$shared/tools/slurm-local.sh"
submit="$root/deploy/slurm/submit.sh"
tmp=$(mktemp -d /tmp/boicp-slurm-test.XXXXXX)
jobs_submitted=()
cluster_started=""

log() { echo "test_slurm: $*"; }
fail() {
  echo "test_slurm: FAIL: $*" >&2
  exit 1
}
cleanup() {
  local code=$?
  set +e
  if [ "$code" -ne 0 ]; then
    for f in "$tmp"/*/logs/*.out; do
      [ -f "$f" ] && { echo "--- $f" >&2; tail -n 5 "$f" >&2; }
    done
  fi
  [ "${#jobs_submitted[@]}" -gt 0 ] && scancel "${jobs_submitted[@]}" 2>/dev/null
  [ -n "$cluster_started" ] && bash "$slurm_local" stop
  rm -rf "$tmp"
  exit "$code"
}
trap cleanup EXIT
elapsed() { echo $(($(date +%s) - $1)); }

[ -f "$slurm_local" ] || fail "$slurm_local not found"
export PATH="$bin:$PATH"
cluster_started=1
start=$(date +%s)
bash "$slurm_local" start >"$tmp/slurm-start.log" 2>&1 \
  || { cat "$tmp/slurm-start.log" >&2; fail "slurm-local.sh start"; }
log "cluster up in $(elapsed "$start") s: $(sinfo -h -o '%P %T %c CPUs')"

kitti="$shared/data/kitti00"
if [ -d "$kitti/velodyne" ]; then
  scans="$kitti"
  flags=(--rotation-bounds "0.2,0.2,3.14159")  # a ground vehicle
else
  scans="$tmp/drive"
  boicp demo-data --scans 10 --out "$scans" >/dev/null
  flags=()
  log "$kitti absent: a generated drive of 10 scans"
fi

# Terminal state of job ID (waits up to 900 s): COMPLETED, FAILED, CANCELLED, ...
wait_job() {
  local id=$1 state start
  start=$(date +%s)
  while [ "$(elapsed "$start")" -lt 900 ]; do
    state=$(scontrol show job -o "$id" | grep -o 'JobState=[A-Z_]*' | head -n 1 | cut -d= -f2)
    case "$state" in
      PENDING | RUNNING | CONFIGURING | COMPLETING | SUSPENDED | REQUEUED | "") sleep 1 ;;
      *) echo "$state"; return 0 ;;
    esac
  done
  fail "job $id did not end within 900 s"
}
# Waits until no task of array job ID is pending or running.
wait_array() {
  local id=$1 start
  start=$(date +%s)
  while squeue -h -r -o %i | grep -q "^${id}_"; do
    [ "$(elapsed "$start")" -lt 900 ] || fail "array $id did not end within 900 s"
    sleep 1
  done
}
# Submits with the wrapper; sets array and merge.
submit_run() {
  local ids
  ids=$("$submit" "$scans" "$1" --shards 3 "${flags[@]}") || fail "submit.sh $1"
  [ "$(wc -l <<<"$ids")" = 2 ] || fail "submit.sh printed '$ids', want two job ids"
  array=$(sed -n 1p <<<"$ids")
  merge=$(sed -n 2p <<<"$ids")
  jobs_submitted+=("$array" "$merge")
}
# The pair files of OUTDIR with their inode and mtime (ns), one a line.
pair_files() { (cd "$1/pairs" && stat -c '%n %i %.9Y' -- *.json 2>/dev/null | sort) || true; }

# --------------------------------------------------- one map run, the reference

start=$(date +%s)
boicp map "$scans" -o "$tmp/single" --threads 2 "${flags[@]}" >"$tmp/single.log" 2>&1 \
  || { tail -n 20 "$tmp/single.log" >&2; fail "boicp map (single run)"; }
pairs_total=$(($(wc -l <"$tmp/single/trajectory.kitti") - 1))
log "single boicp map: $pairs_total pairs in $(elapsed "$start") s"

# -------------------------------------------------- 3 shards, then the merge

start=$(date +%s)
submit_run "$tmp/sharded"
log "submitted array $array and merge $merge"
state=$(wait_job "$merge")
[ "$state" = COMPLETED ] || fail "merge job $merge ended $state"
for f in map.bt map.ot trajectory.tum trajectory.kitti pairs.json preview.png; do
  [ -s "$tmp/sharded/$f" ] || fail "the merge wrote no $f into OUTDIR"
done
cmp "$tmp/single/trajectory.kitti" "$tmp/sharded/trajectory.kitti" \
  || fail "the merged trajectory.kitti differs from the single run's"
log "3 shards + merge in $(elapsed "$start") s: trajectory.kitti identical to the single run"

# ------------------------------------------- a cancelled task, then a resubmit

start=$(date +%s)
out="$tmp/resumed"
submit_run "$out"
# Shard 2/3 owns the pairs whose index mod 3 is 1: 1->2, 4->5, 7->8, ...
shard2=()
for ((i = 1; i < pairs_total; i += 3)); do shard2+=("$(printf '%06d-%06d.json' "$i" $((i + 1)))"); done
while [ ! -f "$out/pairs/${shard2[0]}" ]; do
  [ "$(elapsed "$start")" -lt 600 ] || fail "shard 2 wrote no pair within 600 s"
  sleep 0.2
done
scancel "${array}_2"
wait_array "$array"
state=$(wait_job "$merge")
[ "$state" = CANCELLED ] || fail "merge $merge ended $state after a shard was cancelled, want CANCELLED"
[ ! -e "$out/trajectory.kitti" ] || fail "a trajectory was written without every shard"
task2=$(scontrol show job -o "${array}_2" | grep -o 'JobState=[A-Z_]*' | cut -d= -f2)
[ "$task2" = CANCELLED ] || fail "task ${array}_2 ended $task2, want CANCELLED"
missing=()
for f in "${shard2[@]}"; do [ -f "$out/pairs/$f" ] || missing+=("$f"); done
[ "${#missing[@]}" -gt 0 ] || fail "task 2 finished all its pairs before it was cancelled"
pair_files "$out" >"$tmp/before.txt"
log "task ${array}_2 cancelled with ${#missing[@]} of ${#shard2[@]} pairs missing; merge cancelled"

submit_run "$out"
state=$(wait_job "$merge")
[ "$state" = COMPLETED ] || fail "merge job $merge ended $state after the resubmit"
pair_files "$out" >"$tmp/after.txt"
# Every file written before is untouched (same inode and mtime)...
untouched=$(comm -23 "$tmp/before.txt" "$tmp/after.txt")
[ -z "$untouched" ] || fail "the resubmit rewrote pair files: $untouched"
# ...and the new ones are exactly the cancelled task's missing pairs.
new=$(comm -13 "$tmp/before.txt" "$tmp/after.txt" | cut -d' ' -f1 | tr '\n' ' ')
want=$(printf '%s\n' "${missing[@]}" | sort | tr '\n' ' ')
[ "$new" = "$want" ] || fail "the resubmit registered '$new', want '$want'"
# The tasks' own accounting agrees: only the missing pairs were registered.
registered=$(cat "$out"/logs/map-"${array}"_*.out | sed -n 's/^[0-9]* pairs (\([0-9]*\) registered.*/\1/p' \
  | awk '{ s += $1 } END { print s + 0 }')
[ "$registered" = "${#missing[@]}" ] || fail "the resubmitted tasks registered $registered pairs, want ${#missing[@]}"
cmp "$tmp/single/trajectory.kitti" "$out/trajectory.kitti" \
  || fail "the resumed run's trajectory.kitti differs from the single run's"
log "resubmit registered only ${missing[*]}; trajectory.kitti identical; $(elapsed "$start") s"
log "ok"
