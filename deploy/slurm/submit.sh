#!/usr/bin/env bash
# Submits a sharded `boicp map` run to Slurm: an array of N shard tasks, then a
# merge job that starts only when every task succeeded. Prints the two job ids
# (array, then merge), one a line. The jobs run the `boicp` on PATH at
# submission (sbatch exports the environment); logs go to OUTDIR/logs/.
# The merge writes the map (map.bt, map.ot, trajectory.tum, trajectory.kitti,
# pairs.json, preview.png) into OUTDIR. Submitting again with the same
# arguments resumes: shards skip the pairs already in OUTDIR/pairs/.
# Usage: deploy/slurm/submit.sh SCAN_FOLDER OUTDIR [--shards N] [boicp map flags...]
#   --shards N   number of array tasks (default 4); each registers about 1/N of the pairs
# Extra sbatch options (partition, account, time) go in SBATCH_* variables,
# e.g. SBATCH_PARTITION=main, which sbatch reads itself.
set -euo pipefail

usage() {
  echo "usage: $0 SCAN_FOLDER OUTDIR [--shards N] [boicp map flags...]" >&2
  exit 2
}
[ $# -ge 2 ] || usage
here=$(cd "$(dirname "$0")" && pwd)
# Jobs may start in another directory: hand them absolute paths.
scans=$(realpath -e -- "$1") || { echo "submit.sh: scan folder $1 not found" >&2; exit 2; }
mkdir -p -- "$2"
out=$(realpath -e -- "$2")
shift 2
shards=4
if [ "${1:-}" = "--shards" ]; then
  [ $# -ge 2 ] || usage
  shards=$2
  shift 2
fi
case "$shards" in
  '' | *[!0-9]* | 0*) echo "submit.sh: --shards wants a positive integer, got '$shards'" >&2; exit 2 ;;
esac
command -v boicp >/dev/null || { echo "submit.sh: no boicp on PATH" >&2; exit 2; }
command -v sbatch >/dev/null || { echo "submit.sh: no sbatch on PATH" >&2; exit 2; }
mkdir -p -- "$out/logs"

array=$(sbatch --parsable --array="1-$shards" --output="$out/logs/map-%A_%a.out" \
  "$here/map-shards.sbatch" "$scans" "$out" "$@")
array=${array%%;*}  # --parsable prints "id;cluster" on multi-cluster setups
# A failed or cancelled shard cancels the merge instead of leaving it pending forever.
merge=$(sbatch --parsable --dependency="afterok:$array" --kill-on-invalid-dep=yes \
  --output="$out/logs/merge-%j.out" "$here/merge.sbatch" "$out")
merge=${merge%%;*}
echo "$array"
echo "$merge"
