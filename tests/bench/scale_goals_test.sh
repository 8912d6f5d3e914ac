#!/usr/bin/env bash
# scripts/scale_goals.sh in its quick mode: every goal gets a figure from every round, the summary
# a line per goal with its target, median and verdict; and the script's refusals (exit code 2, a
# message naming what is wrong). Asserts nothing on the figures themselves (they are times).
# Usage: scale_goals_test.sh SOURCE_DIR JELLY_BENCH JELLY WORK_DIR
set -euo pipefail
source_dir=$1 bench=$2 jelly=$3 work=$4
script=$source_dir/scripts/scale_goals.sh
rm -rf "$work"
mkdir -p "$work"
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
export JELLY_BENCH=$bench JELLY=$jelly

bash "$script" --quick --rounds 2 --out "$work/out" >"$work/stdout" \
  2>"$work/stderr" || fail "the quick run failed: $(cat "$work/stderr")"
figures=$work/out/rounds.csv
goals=(rk4_speedup_n4 rk4_speedup_n6 implicit_speedup_n4 implicit_speedup_n6
  implicit_slope_step_ms_n6 xpbd_frame_ms_n4 xpbd_frame_ms_n6)
[[ -x /usr/bin/time ]] && goals+=(implicit_slope_peak_mb_n6)
for goal in "${goals[@]}"; do
  for round in 1 2; do
    value=$(awk -F, -v g="$goal" -v r="$round" '$1 == r && $2 == g { print $3 }' "$figures")
    [[ $value =~ ^-?[0-9]+(\.[0-9]+)?$ ]] || fail "round $round: $goal is '$value', not a number"
  done
done
rows=$(($(wc -l <"$figures") - 1))
[[ $rows == $((2 * ${#goals[@]})) ]] || fail "rounds.csv has $rows figures, not $((2 * ${#goals[@]}))"
# The summary: a line per goal, each with its target, a median and a verdict.
lines=$(grep -cE '(>=|<=) [0-9.]+ +-?[0-9.]+ .* (yes|no)$' "$work/out/summary.txt" || true)
[[ $lines == "${#goals[@]}" ]] || fail "summary has $lines goal lines, not ${#goals[@]}: $(cat "$work/out/summary.txt")"
cmp -s "$work/stdout" "$work/out/summary.txt" || fail "stdout is not the summary"
grep -q "quick" "$work/out/summary.txt" || fail "the summary does not say it is a quick run"

# Refusals.
refuse() {
  local what=$1
  shift
  local rc=0
  bash "$script" "$@" >"$work/refused" 2>&1 || rc=$?
  [[ $rc == 2 ]] || fail "$what: exit code $rc, not 2"
  grep -qF -- "$what" "$work/refused" || fail "$what: message is $(cat "$work/refused")"
}
refuse "--rounds takes a whole number" --rounds 0
refuse "--rounds takes a whole number" --rounds
refuse "unknown argument '--fast'" --fast
refuse "--out takes a directory" --out
refuse "is not empty" --quick --out "$work/out"
# --overwrite: a second run into the same directory, with one round, leaves no second round.
bash "$script" --quick --rounds 1 --out "$work/out" --overwrite >/dev/null 2>&1 ||
  fail "the run with --overwrite failed"
[[ ! -e $work/out/round2 ]] || fail "--overwrite left the earlier run's round2"
JELLY_BENCH=$work/none refuse "jelly-bench not found at $work/none" --quick
echo "scale_goals.sh: ok"
