#!/usr/bin/env bash
# bench/slurm/suite-array.sh on a real Slurm cluster: scripts/slurm-local brings up a one-node cluster on
# this machine, the quick suite runs as 2 array tasks plus the merge job, and the merged results must equal
# an unsharded run of the same suite apart from timings: the same cells in the same order and, per cell,
# the same status, geometry hash and counts (what tests/harness/suite_test.cpp checks for `growbench merge`
# without Slurm). On the way, one shard is cut back to an interrupted run and --resubmit-failed must rerun
# that shard alone, from its journal. A cluster that does not come up is a failure, not a skip: CI installs
# and starts it.
# The cluster is always brought down at the end.
# usage: slurm_test.sh GROWBENCH [WORKDIR]   (as root, from the repository root)
set -euo pipefail
usage="usage: slurm_test.sh GROWBENCH [WORKDIR]"
G=${1:?$usage}
W=${2:-${TMPDIR:-/tmp}/growbench-slurm-test}
PY=/usr/bin/python3
# Bounds: the quick suite takes a minute or two unsharded on 2 cores; its two shards run one after the other.
WAIT_S=900

[[ -x "$G" ]] || { echo "FAIL: $G is not an executable growbench" >&2; exit 1; }
G=$(cd "$(dirname "$G")" && pwd)/$(basename "$G")
rm -rf "$W"
mkdir -p "$W"
W=$(cd "$W" && pwd)
cd "$(dirname "$0")/../.."

# The clients below find our cluster whatever /etc/slurm holds (scripts/slurm-local, "Finding the configuration").
state=${GROWBENCH_SLURM_DIR:-/var/lib/growbench-slurm}
export SLURM_CONF=$state/etc/slurm.conf

now() { date +%s.%N; }
took() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f s", b - a }'; }
daemon_logs() {
  local f
  for f in "$state/log/slurmctld.log" "$state/log/slurmd.log"; do
    echo "---- $f ----" >&2
    if [[ -f "$f" ]]; then tail -n 80 "$f" >&2; else echo "(none)" >&2; fi
  done
}
fail() {
  echo "FAIL: $*" >&2
  exit 1
}

verdict=""
cleanup() {
  local rc=$? t
  t=$(now)
  if ! scripts/slurm-local down; then
    echo "FAIL: scripts/slurm-local down left Slurm running" >&2
    rc=1
  fi
  echo "slurm_test: down took $(took "$t")"
  if ((rc == 0)); then echo "slurm_test: $verdict, PASS"; else echo "slurm_test: FAIL"; fi
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

t=$(now)
if ! scripts/slurm-local up; then
  daemon_logs
  fail "the local Slurm cluster did not come up (scripts/slurm-local up)"
fi
echo "slurm_test: up took $(took "$t")"
sinfo

# 1. Sharded under Slurm: 2 array tasks and the merge job; the suite's path is relative, as a user gives it.
t=$(now)
if ! GROWBENCH="$G" bench/slurm/suite-array.sh --wait="$WAIT_S" bench/suites/quick.json "$W/sharded" 2; then
  for f in "$W"/sharded/logs/*.log; do
    echo "---- $f ----" >&2
    tail -n 40 "$f" >&2
  done
  squeue >&2 || true
  daemon_logs
  fail "the sharded run under Slurm did not finish (logs above)"
fi
echo "slurm_test: sharded run under Slurm took $(took "$t")"

# The jobs really ran as Slurm jobs: each wrote its Slurm log, and the merge joined 2 shards.
for f in shard-0 shard-1 merge; do
  grep -q "^suite-array: job [0-9]" "$W/sharded/logs/$f.log" 2> /dev/null || fail "no Slurm job log $W/sharded/logs/$f.log"
done
grep -q "merged 2 shards" "$W/sharded/logs/merge.log" || fail "merge.log does not show a merge of 2 shards"

# 2. A shard interrupted before its first snapshot (as by kill -9): its results.json gone, the first lines of
# its journal kept. --resubmit-failed submits that shard alone, which resumes from the journal, and a new merge.
rm "$W/sharded/shard-1/results.json"
head -n 3 "$W/sharded/shard-1/journal.jsonl" > "$W/journal.jsonl"
mv "$W/journal.jsonl" "$W/sharded/shard-1/journal.jsonl"
t=$(now)
if ! GROWBENCH="$G" bench/slurm/suite-array.sh --resubmit-failed --wait="$WAIT_S" bench/suites/quick.json "$W/sharded" 2 |
  tee "$W/resubmit.txt"; then
  tail -n 40 "$W/sharded/logs/shard-1.log" "$W/sharded/logs/merge.log" >&2
  fail "the resubmitted shard did not finish"
fi
grep -q "shards 1 of 2" "$W/resubmit.txt" || fail "--resubmit-failed did not submit exactly the interrupted shard 1"
[[ $(grep -c "^suite-array: job [0-9]*, shard 1/2" "$W/sharded/logs/shard-1.log") -eq 2 ]] ||
  fail "shard-1.log does not show the resubmitted run after the first"
[[ $(grep -c "^suite-array: job [0-9]*, shard 0/2" "$W/sharded/logs/shard-0.log") -eq 1 ]] || fail "shard 0 ran again"
echo "slurm_test: resubmitting the interrupted shard took $(took "$t")"

# A folder whose name Slurm would read as a pattern is refused before anything is submitted.
if GROWBENCH="$G" bench/slurm/suite-array.sh bench/suites/quick.json "$W/job-%j" 2 > "$W/pattern.txt" 2>&1 ||
  ! grep -q "OUT_DIR: '$W/job-%j' holds '%'" "$W/pattern.txt" || [[ -e "$W/job-%j" ]]; then
  cat "$W/pattern.txt" >&2
  fail "an OUT_DIR with %j was not refused"
fi

# 3. Unsharded, directly.
t=$(now)
if ! "$G" suite bench/suites/quick.json --out "$W/unsharded" -q > "$W/unsharded.txt" 2>&1; then
  cat "$W/unsharded.txt" >&2
  fail "the unsharded run failed"
fi
echo "slurm_test: unsharded run took $(took "$t")"

# 4. The same cells in the same order, and per cell the same status, geometry hash and counts.
verdict=$($PY - "$W/sharded/results.json" "$W/unsharded/results.json" << 'EOF'
import difflib, json, sys

merged, full = (json.load(open(p)) for p in sys.argv[1:3])
problems = []
if len(merged.get("shards", [])) != 2:
    problems.append(f"the merged file lists {len(merged.get('shards', []))} shards, not 2")
ids_m = [t["id"] for t in merged["trials"]]
ids_f = [t["id"] for t in full["trials"]]
if ids_m != ids_f:
    problems.append("cells differ (--- unsharded, +++ merged):\n" + "\n".join(
        difflib.unified_diff(ids_f, ids_m, "unsharded", "merged", lineterm="")))
else:
    reps = full["repetitions"]
    for m, f in zip(merged["trials"], full["trials"]):
        for key in ("status", "geometry_hash", "counts"):
            if m.get(key) != f.get(key):
                problems.append(f"{m['id']}: {key}: merged {json.dumps(m.get(key))}, unsharded {json.dumps(f.get(key))}")
        for name, t in (("merged", m), ("unsharded", f)):
            if len(t["samples"]) != reps:
                problems.append(f"{t['id']}: {name} has {len(t['samples'])} repetitions, not {reps}")
if problems:
    print("slurm_test: the merged results differ from the unsharded run:", file=sys.stderr)
    for p in problems:
        print("  " + p, file=sys.stderr)
    sys.exit(1)
print(f"{len(ids_m)} cells equal")
EOF
)
