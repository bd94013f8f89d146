#!/usr/bin/env bash
# Run a growbench suite sharded across a Slurm job array, then merge the shards into one results file.
#
#   bench/slurm/suite-array.sh [--wait[=SECONDS]] SUITE.json OUT_DIR [SHARDS]
#   bench/slurm/suite-array.sh --resubmit-failed [--wait[=SECONDS]] SUITE.json OUT_DIR SHARDS
#
# (from the repository root, after `make build`; GROWBENCH names another growbench binary.)
#
# Submits SHARDS array tasks (default 8); task I runs `growbench suite SUITE --shard I/SHARDS --resume` into
# OUT_DIR/shard-I on its own node (each trial still runs in its own process there), and a final job that
# starts when every task has succeeded runs `growbench merge` into OUT_DIR/results.json, in the same cell
# order as an unsharded run (timings aside, identical to one: tests/harness/suite_test.cpp checks it, and
# tests/harness/slurm_test.sh on a real one-node cluster). Logs go to OUT_DIR/logs/shard-I.log and merge.log
# (appended to, so a resubmitted shard's log keeps the failed attempt above the new one).
#
# If a task fails (killed, timed out, its node lost), the merge job is cancelled rather than left pending.
# --resubmit-failed then submits only the shards whose OUT_DIR/shard-I/results.json is missing or incomplete
# (an interrupted shard keeps its journal.jsonl and continues from it with --resume), e.g. as --array=1,3,
# and a new merge job that waits for them. SHARDS must be the number the run was started with.
#
# --wait blocks until the merge job has finished (at most SECONDS, default a day) and exits non-zero if it
# or any shard failed, saying which shards to resubmit. Without it the script returns after submitting.
# Job states are read with scontrol, which forgets a job some minutes after it ends (MinJobAge); sacct would
# need an accounting database, which a small cluster may not have.
#
# Timings from different nodes are only comparable on identical nodes: pin the partition or constraint
# with GROWBENCH_SBATCH_ARGS (e.g. "--partition=bench --exclusive"); it is passed to the merge job too (a
# site may require an account or partition for every job). Each shard keeps its own context.
# Paths are made absolute and every job runs in OUT_DIR (--chdir), so the jobs do not depend on the
# directory this script was started from; OUT_DIR and the binary must be visible on the compute nodes.
set -euo pipefail
usage="usage: suite-array.sh [--resubmit-failed] [--wait[=SECONDS]] SUITE.json OUT_DIR [SHARDS]"
die() { echo "suite-array: $*" >&2; exit 2; }

resubmit=0
wait_s=""
while [[ $# -gt 0 && "$1" == --* ]]; do
  case "$1" in
    --resubmit-failed) resubmit=1 ;;
    --wait) wait_s=86400 ;;
    --wait=*) wait_s=${1#--wait=} ;;
    --help) echo "$usage"; exit 0 ;;
    *) die "unknown option $1; $usage" ;;
  esac
  shift
done
[[ -z "$wait_s" || "$wait_s" =~ ^[0-9]+$ ]] || die "--wait=SECONDS: '$wait_s' is not a number of seconds"
[[ $# -ge 2 && $# -le 3 ]] || die "$usage"
suite=$1
out=$2
if ((resubmit)); then
  shards=${3:?--resubmit-failed needs SHARDS, the number the run was started with}
else
  shards=${3:-8}
fi
[[ "$shards" =~ ^[1-9][0-9]*$ ]] || die "SHARDS: '$shards' is not a positive number"

gb=${GROWBENCH:-$(pwd)/build/release/harness/growbench}
if [[ "$gb" != */* ]]; then gb=$(command -v "$gb" || echo "$gb"); fi
command -v sbatch > /dev/null || die "sbatch not found (this script submits Slurm jobs)"
[[ -x "$gb" ]] || die "$gb is not built (make build, or set GROWBENCH)"
[[ -f "$suite" ]] || die "$suite: no such suite file"
# The jobs run elsewhere (another node, OUT_DIR as their directory): absolute paths only.
gb=$(cd "$(dirname "$gb")" && pwd)/$(basename "$gb")
suite=$(cd "$(dirname "$suite")" && pwd)/$(basename "$suite")
# Slurm reads --output as a pattern (%j, %a; a backslash stops it), and a control character would end the
# lines of the script sbatch --wrap writes: the folder must name itself.
unsafe_path() { [[ "$1" == *%* || "$1" == *\\* || "$1" =~ [[:cntrl:]] ]]; }
! unsafe_path "$out" || die "OUT_DIR: '$out' holds '%', '\\' or a control character, which Slurm would read as part of a pattern; choose a folder name without them"
mkdir -p "$out/logs"
out=$(cd "$out" && pwd)
! unsafe_path "$out" || die "OUT_DIR: its absolute path '$out' holds '%', '\\' or a control character, which Slurm would read as part of a pattern; run from a folder without them"

# Single-quotes a word for the /bin/sh script that sbatch --wrap writes (any character is safe inside '').
q() { printf "'%s'" "${1//\'/\'\\\'\'}"; }

# The shards (0-based) whose results.json is missing or does not hold every repetition of every cell.
incomplete_shards() {
  /usr/bin/env python3 - "$out" "$shards" << 'EOF'
import json, os, sys
out, n = sys.argv[1], int(sys.argv[2])
bad = []
for i in range(n):
    try:
        with open(os.path.join(out, f"shard-{i}", "results.json")) as f:
            r = json.load(f)
        shard = r.get("shard", {})
        if (shard.get("index"), shard.get("count")) != (i, n):
            sys.exit(f"suite-array: {out}/shard-{i} is shard {shard.get('index')}/{shard.get('count')}, not {i}/{n}")
        reps = r["repetitions"]
        if any(t.get("status") == "pending" or len(t.get("samples", [])) < reps for t in r["trials"]):
            bad.append(i)
    except (OSError, ValueError, KeyError, TypeError):
        bad.append(i)
print(",".join(map(str, bad)))
EOF
}

# sbatch --parsable prints "JOBID" or "JOBID;CLUSTER".
submit() { local id; id=$(sbatch --parsable "$@") || return 1; echo "${id%%;*}"; }

submitted_at=$(date +%s)
# shellcheck disable=SC2206
site_args=(${GROWBENCH_SBATCH_ARGS:-})
if ((resubmit)); then
  array_spec=$(incomplete_shards)
else
  array_spec=0-$((shards - 1))
fi

# A task runs the suite's trials one after another, each with the suite's "threads": it asks for that many
# CPUs (GROWBENCH_CPUS_PER_TASK overrides), or for a whole node where the suite uses every core (threads 0).
cpus=${GROWBENCH_CPUS_PER_TASK:-$(/usr/bin/env python3 -c 'import json, sys; print(int(json.load(open(sys.argv[1])).get("threads", 0)))' "$suite")}
[[ "$cpus" =~ ^[0-9]+$ ]] || die "GROWBENCH_CPUS_PER_TASK: '$cpus' is not a number"
if ((cpus > 0)); then cpu_args=(--cpus-per-task="$cpus"); else cpu_args=(--exclusive); fi

array=""
dependency=()
if [[ -n "$array_spec" ]]; then
  array=$(submit "${site_args[@]}" --job-name=growbench-suite --array="$array_spec" "${cpu_args[@]}" \
    --chdir="$out" --output="$out/logs/shard-%a.log" --open-mode=append \
    --wrap="echo \"suite-array: job \$SLURM_JOB_ID, shard \$SLURM_ARRAY_TASK_ID/$shards on \$(hostname), \$(date)\"
exec $(q "$gb") suite $(q "$suite") --shard \"\$SLURM_ARRAY_TASK_ID/$shards\" --out $(q "$out")/shard-\"\$SLURM_ARRAY_TASK_ID\" --resume -q")
  # afterok: the merge runs only if every task succeeded; otherwise it is cancelled, not left pending forever.
  dependency=(--dependency=afterok:"$array" --kill-on-invalid-dep=yes)
  echo "submitted array job $array: shards $array_spec of $shards of $(basename "$suite")"
else
  echo "every one of the $shards shards in $out is complete; submitting only the merge"
fi

inputs=""
for ((i = 0; i < shards; i++)); do inputs+=" $(q "$out/shard-$i/results.json")"; done
merge=$(submit "${site_args[@]}" --job-name=growbench-merge "${dependency[@]}" --cpus-per-task=1 \
  --chdir="$out" --output="$out/logs/merge.log" --open-mode=append \
  --wrap="echo \"suite-array: job \$SLURM_JOB_ID, merge on \$(hostname), \$(date)\"
exec $(q "$gb") merge$inputs --out $(q "$out/results.json")")
echo "submitted merge job $merge; results: $out/results.json, logs: $out/logs"

[[ -z "$wait_s" ]] && exit 0

# --wait: poll the merge job until it leaves the queue. A job that scontrol no longer knows ended long ago
# (MinJobAge): UNKNOWN, judged by the files below. No answer at all (slurmctld busy): ask again.
job_state() {
  local info
  info=$(scontrol show job -o "$1" 2>&1 || true)
  if [[ "$info" == *"Invalid job id"* ]]; then echo UNKNOWN; else sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' <<< "$info" | head -n 1; fi
}
started=$SECONDS
state=""
while true; do
  state=$(job_state "$merge")
  case "$state" in
    PENDING | RUNNING | CONFIGURING | COMPLETING | SUSPENDED | REQUEUED | RESIZING | "") ;;
    *) break ;;
  esac
  if ((SECONDS - started >= wait_s)); then
    echo "suite-array: still not finished after ${wait_s} s (merge job $merge ${state:-?}); the jobs stay queued" >&2
    exit 2
  fi
  sleep 2
done

# The verdict: the shards' files (complete or not) and, while scontrol still knows them, the tasks' states.
failed=$(incomplete_shards)
task_failed=""
if [[ -n "$array" ]]; then
  echo "array job $array:"
  tasks=$(scontrol show job -o "$array" 2> /dev/null |
    sed -n 's/.*ArrayTaskId=\([^ ]*\).*JobState=\([A-Z_]*\).*ExitCode=\([^ ]*\).*/\1 \2 \3/p' | sort -n || true)
  while read -r task st code; do
    [[ -n "$task" ]] || continue
    echo "  shard $task: $st (exit $code)"
    [[ "$st" == COMPLETED ]] || task_failed+="${task_failed:+,}$task"
  done <<< "$tasks"
fi
echo "merge job $merge: $state after $((SECONDS - started)) s"
[[ -z "$task_failed" ]] || echo "suite-array: shard tasks $task_failed failed (see $out/logs/shard-I.log)" >&2
if [[ -n "$failed" ]]; then
  echo "suite-array: shards $failed of $shards are incomplete; continue them with:" >&2
  echo "  $(printf '%q ' "$0" --resubmit-failed "$suite" "$out" "$shards")" >&2
  exit 1
fi
merged_at=$(stat -c %Y "$out/results.json" 2> /dev/null || echo 0)
if [[ -n "$task_failed" || ("$state" != COMPLETED && ! ("$state" == UNKNOWN && "$merged_at" -ge "$submitted_at")) ]]; then
  echo "suite-array: the merge job ended ${state} (see $out/logs/merge.log)" >&2
  exit 1
fi
echo "merged: $out/results.json"
