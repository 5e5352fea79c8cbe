#!/bin/bash
# Submits a camchain sweep as a Slurm job array and its merge as a job that waits for it.
#
#   scripts/slurm/submit.sh DIR MODEL SHARDS AT_ONCE "NAME=VALUES ..." [--wait]
#
# e.g. scripts/slurm/submit.sh run paper_concave 8 2 "swing=-0.5:0.5:100 k3=20:80:50"
# runs shards 1..8, at most 2 at a time, into run/shards/, then merges them into
# run/sweep.csv; logs go to run/logs/. CAMCHAIN_OPTIONS and CAMCHAIN pass on to the tasks
# (see sweep.sbatch). With --wait the script returns when the merge has run, with its exit
# status: non-zero when a shard failed (the merge is then cancelled: its dependency can never
# be met) or the merge refused the shards. Prints the two job ids.
set -euo pipefail
if [[ $# -lt 5 ]]; then
    sed -n '2,11p' "$0" >&2
    exit 2
fi
dir=$1 model=$2 shards=$3 at_once=$4 params=$5 wait=${6:-}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$dir/logs"
export CAMCHAIN_DIR=$dir CAMCHAIN_MODEL=$model CAMCHAIN_SHARDS=$shards CAMCHAIN_PARAMS=$params
array=$(sbatch --parsable --array="1-$shards%$at_once" --export=ALL \
    --output="$dir/logs/shard-%a.log" "$here/sweep.sbatch")
echo "sweep: job array $array"
merge_args=(--parsable --dependency="afterok:${array%%;*}" --kill-on-invalid-dep=yes
    --export=ALL --output="$dir/logs/merge.log")
if [[ $wait == --wait ]]; then
    merge_args+=(--wait)
fi
merge=$(sbatch "${merge_args[@]}" "$here/merge.sbatch")
echo "merge: job ${merge%%;*}"
