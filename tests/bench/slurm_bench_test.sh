#!/usr/bin/env bash
# scripts/slurm_bench.sh with a stand-in sbatch that runs each submitted job at once, in order,
# as Slurm would give it: every task of an array with its SLURM_ARRAY_TASK_ID (and the job's
# environment), a dependent job after them. Checks the merged table against an unsharded run
# and the script's refusals (exit code 2, a message naming what is wrong).
# Usage: slurm_bench_test.sh SOURCE_DIR JELLY_BENCH WORK_DIR
set -euo pipefail
source_dir=$1 bench=$2 work=$3
script=$source_dir/scripts/slurm_bench.sh
rm -rf "$work"
mkdir -p "$work/bin"
fail() {
  echo "FAIL: $*" >&2
  exit 1
}

# The stand-in: sbatch [--parsable] [--export=..] [--array=A-B] [--dependency=..] [--output=..] SCRIPT ARGS
cat >"$work/bin/sbatch" <<'EOF'
#!/usr/bin/env bash
set -euo pipefail
array=""
while [[ $1 == --* ]]; do
  case $1 in
    --array=*) array=${1#--array=} ;;
  esac
  echo "$1" >>"$SBATCH_LOG"
  shift
done
id=$(($(cat "$SBATCH_IDS" 2>/dev/null || echo 100) + 1))
echo "$id" >"$SBATCH_IDS"
if [[ -n $array ]]; then
  for ((i = ${array%-*}; i <= ${array#*-}; ++i)); do
    SLURM_ARRAY_JOB_ID=$id SLURM_ARRAY_TASK_ID=$i bash "$@" >"$SBATCH_DIR/task-$i.out" 2>&1
  done
else
  bash "$@" >"$SBATCH_DIR/job-$id.out" 2>&1
fi
echo "$id"
EOF
chmod +x "$work/bin/sbatch"
export SBATCH_LOG=$work/sbatch.log SBATCH_IDS=$work/ids SBATCH_DIR=$work
export JELLY_BENCH=$bench

# A sweep of 3 shards, submitted from another directory, and the merge after them.
(cd "$work" && PATH=$work/bin:$PATH SBATCH_FLAGS="--time=00:10:00 --exclusive" \
  bash "$script" submit 3 sweep budget --quick >submit.out) || fail "submit: $(cat "$work/submit.out")"
grep -q "shards job 101 (array 0-2)" "$work/submit.out" && grep -q "merge job 102, after job 101" \
  "$work/submit.out" || fail "submit printed: $(cat "$work/submit.out")"
grep -qx -- "--dependency=afterok:101" "$work/sbatch.log" || fail "the merge does not wait for the array"
grep -qx -- "--kill-on-invalid-dep=yes" "$work/sbatch.log" || fail "a failed task would leave the merge pending"
[[ $(grep -cx -- "--exclusive" "$work/sbatch.log") -eq 2 ]] || fail "SBATCH_FLAGS not given to both jobs"
[[ $(grep -cx -- "--output=$work/sweep/shards/%x-%A_%a.out" "$work/sbatch.log") -eq 1 ]] ||
  fail "the tasks' logs are not kept with their shards"
for i in 0 1 2; do
  [[ -s $work/sweep/shards/budget.shard-$i-of-3.csv ]] || fail "no shard $i: $(cat "$work/task-$i.out")"
done
[[ -s $work/sweep/budget.csv ]] || fail "no merged table: $(cat "$work"/job-102.out)"

# The merged table has the unsharded run's work items, in its order, with the same outcome.
"$bench" budget --quick --out "$work/whole" >/dev/null
rows() { grep -v '^#' "$1" | cut -d, -f1-8; }
diff <(rows "$work/whole/budget.csv") <(rows "$work/sweep/budget.csv") ||
  fail "merged items differ from the unsharded run's"

# Refusals: exit code 2 and the reason.
expect_refusal() {
  local what=$1 pattern=$2
  shift 2
  set +e
  "$@" >"$work/refusal.out" 2>&1
  local code=$?
  set -e
  [[ $code -eq 2 ]] || fail "$what: exit code $code, expected 2: $(cat "$work/refusal.out")"
  grep -q -- "$pattern" "$work/refusal.out" || fail "$what: $(cat "$work/refusal.out")"
}
expect_refusal "a second sweep into the same OUT" "already holds shards" \
  env PATH="$work/bin:$PATH" bash "$script" submit 3 "$work/sweep" budget --quick
expect_refusal "N = 0" "N = '0' is invalid" env PATH="$work/bin:$PATH" bash "$script" submit 0 "$work/x" budget
if ! PATH=/usr/bin:/bin command -v sbatch >/dev/null; then
  expect_refusal "no sbatch" "sbatch not found" env PATH=/usr/bin:/bin bash "$script" submit 2 "$work/x" budget
fi
expect_refusal "shard outside an array" "SLURM_ARRAY_TASK_ID is unset" \
  env -u SLURM_ARRAY_TASK_ID bash "$script" shard 2 "$work/x" budget
expect_refusal "index out of range" "an array index in \[0, 2)" \
  env SLURM_ARRAY_TASK_ID=2 bash "$script" shard 2 "$work/x" budget
expect_refusal "unknown mode" "mode = 'run' is invalid" bash "$script" run
expect_refusal "no program" "no jelly-bench program" \
  env JELLY_BENCH="$work/none" bash "$script" merge "$work/x"
echo "slurm_bench.sh: submit, shards, merge and refusals as expected"
