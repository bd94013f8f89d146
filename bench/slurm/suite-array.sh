#!/usr/bin/env bash
# Run a growbench suite sharded across a Slurm job array, then merge the shards into one results file.
#
#   bench/slurm/suite-array.sh SUITE.json OUT_DIR [SHARDS]      (from the repository root, after `make build`)
#
# Submits SHARDS array tasks (default 8); task I runs `growbench suite SUITE --shard I/SHARDS` into
# OUT_DIR/shard-I on its own node (each trial still runs in its own process there), and a final job that
# starts when every task has finished runs `growbench merge` into OUT_DIR/results.json, in the same cell
# order as an unsharded run (timings aside, identical to one: tests/harness/suite_test.cpp checks it).
# Timings from different nodes are only comparable on identical nodes: pin the partition or constraint
# with GROWBENCH_SBATCH_ARGS (e.g. "--partition=bench --exclusive"). Each shard keeps its own context.
set -euo pipefail
suite=${1:?usage: suite-array.sh SUITE.json OUT_DIR [SHARDS]}
out=${2:?usage: suite-array.sh SUITE.json OUT_DIR [SHARDS]}
shards=${3:-8}
gb=${GROWBENCH:-$(pwd)/build/release/harness/growbench}
command -v sbatch > /dev/null || { echo "suite-array: sbatch not found (this script submits Slurm jobs)" >&2; exit 1; }
[[ -x "$gb" ]] || { echo "suite-array: $gb is not built (make build, or set GROWBENCH)" >&2; exit 1; }
mkdir -p "$out/logs"
# shellcheck disable=SC2086
array=$(sbatch --parsable ${GROWBENCH_SBATCH_ARGS:-} --job-name=growbench-suite --array=0-$((shards - 1)) \
  --cpus-per-task=2 --output="$out/logs/shard-%a.log" \
  --wrap="'$gb' suite '$suite' --shard \$SLURM_ARRAY_TASK_ID/$shards --out '$out'/shard-\$SLURM_ARRAY_TASK_ID --resume -q")
inputs=""
for ((i = 0; i < shards; i++)); do inputs+=" '$out/shard-$i/results.json'"; done
merge=$(sbatch --parsable --job-name=growbench-merge --dependency=afterok:"$array" --output="$out/logs/merge.log" \
  --wrap="'$gb' merge$inputs --out '$out/results.json'")
echo "submitted array job $array ($shards shards) and merge job $merge; results: $out/results.json"
