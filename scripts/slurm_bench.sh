#!/usr/bin/env bash
# A jelly-bench sweep as a Slurm job array: one shard per array task, then the merge
# (docs/benchmarking.md, "Sweeps on a Slurm cluster").
#
#   scripts/slurm_bench.sh submit N OUT COMMAND [ARGS...]
#       submits an array of N tasks (task i runs `jelly-bench COMMAND ARGS --shard i/N
#       --out OUT/shards`) and a merge job that starts when all of them succeeded
#       (`jelly-bench merge OUT/shards --out OUT`); prints both job ids.
#   sbatch --array=0-(N-1) scripts/slurm_bench.sh shard N OUT COMMAND [ARGS...]
#       a task of the array (what `submit` submits): shard $SLURM_ARRAY_TASK_ID of N. Also
#       for rerunning failed tasks alone, e.g. `--array=3,5`, from the checkout's directory
#       (or with JELLY_BENCH exported); add `--output=OUT/shards/%x-%A_%a.out` to keep their
#       logs with the others'.
#   scripts/slurm_bench.sh merge OUT
#       the merge alone (also after a partial rerun of failed tasks).
#
# Environment: JELLY_BENCH, the jelly-bench program (default: build/bench/jelly-bench of this
# checkout, else jelly-bench on PATH); SBATCH_FLAGS, extra sbatch flags for both jobs (e.g.
# "--partition=short --time=02:00:00"). Each task uses the cores Slurm gives it (jelly's
# default `threads` is the process's CPU affinity); set them with `--cpus-per-task` in
# SBATCH_FLAGS; for timed commands (speed, budget) add --exclusive, or tasks sharing a node
# time each other. Exit codes: those of jelly-bench; 2 for a wrong use of this script.
#SBATCH --job-name=jelly-bench
#SBATCH --output=jelly-bench-%A_%a.out
set -euo pipefail

usage() {
  echo "error: $1" >&2
  echo "usage: $0 submit N OUT COMMAND [ARGS...] | shard N OUT COMMAND [ARGS...] | merge OUT" >&2
  exit 2
}

# This file's checkout. Slurm runs a copy of the batch script from its spool directory, so
# `submit` passes its own location in JELLY_SOURCE; a task submitted by hand (a rerun) falls
# back to the directory sbatch was run from, the checkout in the examples.
if [[ -n ${JELLY_SOURCE:-} ]]; then
  source_dir=$JELLY_SOURCE
elif [[ -n ${SLURM_JOB_ID:-} && -n ${SLURM_SUBMIT_DIR:-} ]]; then
  source_dir=$SLURM_SUBMIT_DIR
else
  source_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
fi
if [[ -z ${JELLY_BENCH:-} ]]; then
  if [[ -x $source_dir/build/bench/jelly-bench ]]; then
    JELLY_BENCH=$source_dir/build/bench/jelly-bench
  else
    JELLY_BENCH=$(command -v jelly-bench || true)
  fi
fi
[[ -n ${JELLY_BENCH:-} && -x $JELLY_BENCH ]] ||
  usage "no jelly-bench program: build it (make build) or set JELLY_BENCH"
# Absolute, so that the jobs find it from their own working directory.
JELLY_BENCH=$(cd "$(dirname "$JELLY_BENCH")" && pwd)/$(basename "$JELLY_BENCH")

mode=${1:-}
[[ $# -ge 1 ]] && shift
case $mode in
  submit)
    [[ $# -ge 3 ]] || usage "submit needs N, OUT and a jelly-bench command"
    n=$1 out=$2
    shift 2
    [[ $n =~ ^[1-9][0-9]*$ ]] || usage "N = '$n' is invalid: a whole number of tasks, at least 1"
    [[ $1 != merge ]] || usage "COMMAND = merge is invalid: the merge job is submitted for you"
    command -v sbatch >/dev/null || usage "sbatch not found: submit on a Slurm login node"
    # Shards of an earlier sweep would be merged with (or overwritten by) this one's.
    if compgen -G "$out/shards/*.shard-*-of-*.csv" >/dev/null; then
      usage "OUT = '$out' already holds shards of a sweep ($out/shards): choose a new OUT or remove them"
    fi
    mkdir -p "$out/shards"
    out=$(cd "$out" && pwd)
    read -r -a flags <<<"${SBATCH_FLAGS:-}"  # split on blanks: no flag value with a space
    export JELLY_BENCH JELLY_SOURCE=$source_dir
    array=$(sbatch --parsable --export=ALL --array="0-$((n - 1))" ${flags[@]+"${flags[@]}"} \
      --output="$out/shards/%x-%A_%a.out" "$source_dir/scripts/slurm_bench.sh" shard "$n" "$out" "$@")
    array=${array%%;*}  # --parsable prints "jobid[;cluster]"
    echo "submitted: shards job $array (array 0-$((n - 1)))"
    # A failed task cancels the merge (Slurm would otherwise keep it pending for ever).
    merge=$(sbatch --parsable --export=ALL --dependency="afterok:$array" --kill-on-invalid-dep=yes \
      ${flags[@]+"${flags[@]}"} \
      --output="$out/%x-merge-%j.out" "$source_dir/scripts/slurm_bench.sh" merge "$out")
    merge=${merge%%;*}
    echo "submitted: merge job $merge, after job $array; results in $out"
    ;;
  shard)
    [[ $# -ge 3 ]] || usage "shard needs N, OUT and a jelly-bench command"
    n=$1 out=$2
    shift 2
    [[ $n =~ ^[1-9][0-9]*$ ]] || usage "N = '$n' is invalid: a whole number of tasks, at least 1"
    [[ -n ${SLURM_ARRAY_TASK_ID:-} ]] ||
      usage "shard runs as a task of a Slurm job array (SLURM_ARRAY_TASK_ID is unset)"
    [[ $SLURM_ARRAY_TASK_ID =~ ^[0-9]+$ && $SLURM_ARRAY_TASK_ID -lt $n ]] ||
      usage "SLURM_ARRAY_TASK_ID = '$SLURM_ARRAY_TASK_ID' is invalid: an array index in [0, $n)"
    exec "$JELLY_BENCH" "$@" --shard "$SLURM_ARRAY_TASK_ID/$n" --out "$out/shards"
    ;;
  merge)
    [[ $# -eq 1 ]] || usage "merge needs OUT only"
    exec "$JELLY_BENCH" merge "$1/shards" --out "$1"
    ;;
  *)
    usage "mode = '$mode' is invalid: submit, shard or merge"
    ;;
esac
