#!/usr/bin/env bash
# Issue 17's speed and memory goals measured in one go, over alternating rounds, with each goal's
# figures (every round's, their range and median) and whether the median meets it
# (docs/benchmarking.md, "Speed goals in rounds"). The figures in docs/ come from
# shared 2-core virtual machines whose speed changes from minute to minute; this script is how to
# measure the same goals on another machine.
#
#   scripts/scale_goals.sh [--rounds N] [--out DIR] [--quick] [--overwrite]
#
# Each round runs, one after the other:
#   * jelly-bench speed with 1 and 2 threads interleaved: rk4 at n = 20 (1,000 steps of 1 ms) and
#     n = 40 (100 steps); implicit_euler at n = 20 (60 steps of 1/60 s) and n = 40 (10 steps),
#     in blocks of 5 steps. Goal: 2 threads at least 1.8 times as fast as 1.
#   * the n = 40 jelly landing on the coulomb slope with implicit_euler at 1/60 s on 2 threads:
#     30 steps and 1 step, the steps alone = (30-step run - 1-step run) / 29 (the model's set-up
#     is not a step). Goals: at most 150 ms per step, at most 400 MB of peak memory (needs
#     /usr/bin/time, Debian package `time`; else not measured).
#   * xpbd (1 substep) on the seed slope at n = 20 and n = 40, 2 s of 1/60 s frames, 2 threads,
#     the frames alone as above. Goals: at most 16.7 ms (n = 20) and 100 ms (n = 40) per frame.
# --quick: small cubes and few steps, to check that the script runs (its figures are not the
# goals'). Default: 3 rounds, output under out/scale_goals of the current directory (each run's
# CSV or log, rounds.csv with every figure, summary.txt); a DIR that is not empty is refused
# unless --overwrite (which removes the round folders, rounds.csv and summary.txt in it).
#
# Environment: JELLY_BENCH and JELLY, the programs (default: build/bench/jelly-bench and
# build/cli/jelly of this checkout). Run it with nothing else running. Exit codes: 0 (whether
# or not the goals are met), 1 a run failed, 2 a wrong use of this script.
set -euo pipefail
# Decimal points whatever the locale: $EPOCHREALTIME uses the locale's (a comma under de_DE, which
# awk would cut the time at) and sort -g reads the figures by it.
export LC_ALL=C

usage() {
  echo "error: $1" >&2
  echo "usage: $0 [--rounds N] [--out DIR] [--quick] [--overwrite]" >&2
  exit 2
}

rounds=3
out=out/scale_goals
quick=0
overwrite=0
while [[ $# -gt 0 ]]; do
  case $1 in
    --rounds)
      [[ $# -ge 2 && $2 =~ ^[1-9][0-9]*$ ]] || usage "--rounds takes a whole number >= 1"
      rounds=$2
      shift 2
      ;;
    --out)
      [[ $# -ge 2 && -n $2 && $2 != -* ]] || usage "--out takes a directory"
      out=$2
      shift 2
      ;;
    --quick)
      quick=1
      shift
      ;;
    --overwrite)
      overwrite=1
      shift
      ;;
    *) usage "unknown argument '$1'" ;;
  esac
done

root=$(cd -- "$(dirname -- "$0")/.." >/dev/null && pwd)
bench=${JELLY_BENCH:-$root/build/bench/jelly-bench}
jelly=${JELLY:-$root/build/cli/jelly}
[[ -x $bench ]] || usage "jelly-bench not found at $bench (build first, or set JELLY_BENCH)"
[[ -x $jelly ]] || usage "jelly not found at $jelly (build first, or set JELLY)"
scene=$root/scenes/seed_slope.json
[[ -f $scene ]] || usage "scene not found: $scene"

frame=0.0166666666666667
if [[ $quick == 1 ]]; then
  small=4 large=6 rk4_small=40 rk4_large=20 ie_small=4 ie_large=2 frames=6
else
  small=20 large=40 rk4_small=1000 rk4_large=100 ie_small=60 ie_large=10 frames=120
fi
# Nothing of an earlier run into the same DIR is read as this one's or left to look like it, and
# nothing is removed without --overwrite.
if [[ -n $(ls -A -- "$out" 2>/dev/null) ]]; then
  [[ $overwrite == 1 ]] || usage "$out is not empty (an earlier run?): choose another --out, or --overwrite"
  rm -rf -- "$out"/round[0-9]* "$out/summary.txt" "$out/rounds.csv"
fi
mkdir -p -- "$out"
figures=$out/rounds.csv
echo "round,goal,value" >"$figures"

# The two-thread speed-up of a jelly-bench speed CSV: step_seconds at 1 thread / at 2 threads.
speedup() {
  awk -F, '/^#/ { next }
    !header { for (i = 1; i <= NF; i++) col[$i] = i; header = 1; next }
    { t[$col["threads"]] = $col["step_seconds"] }
    END { if (t[1] > 0 && t[2] > 0) printf "%.3f", t[1] / t[2]; else printf "nan" }' "$1"
}

# Runs a command with its output to LOG; stops the script if it fails.
logged() {
  local log=$1
  shift
  "$@" >"$log" 2>&1 || {
    echo "failed: $* (log: $log)" >&2
    exit 1
  }
}

# As logged; prints the command's wall time in seconds. With /usr/bin/time, LOG.time gets its
# peak resident memory (peak_mb reads it).
timed() {
  local log=$1 start end
  shift
  start=$EPOCHREALTIME
  if [[ -x /usr/bin/time ]]; then
    logged "$log" /usr/bin/time -f "peak_kb %M" -o "$log.time" "$@"
  else
    logged "$log" "$@"
  fi
  end=$EPOCHREALTIME
  awk -v s="$start" -v e="$end" 'BEGIN { printf "%.4f", e - s }'
}
peak_mb() { [[ -f $1.time ]] && awk '/^peak_kb/ { printf "%.0f", $2 / 1024 }' "$1.time"; }

# The time of one step of a run of `steps` steps beyond a run of one: (long - short) / (steps - 1),
# in ms.
per_step_ms() { awk -v l="$1" -v s="$2" -v n="$3" 'BEGIN { printf "%.1f", 1000 * (l - s) / (n - 1) }'; }

# A figure that could not be read stops the script (a $(...) in an argument would not).
record() {
  [[ -n $3 ]] || { echo "round $1: no figure for $2" >&2; exit 1; }
  echo "$1,$2,$3" >>"$figures"
}

for r in $(seq "$rounds"); do
  dir=$out/round$r
  mkdir -p "$dir"
  for n in "$small" "$large"; do
    steps=$([[ $n == "$small" ]] && echo "$rk4_small" || echo "$rk4_large")
    logged "$dir/rk4_$n.log" "$bench" speed --integrators rk4 --sizes "$n" --threads 1,2 \
      --steps "$steps" --interleave --out "$dir/rk4_$n"
    record "$r" "rk4_speedup_n$n" "$(speedup "$dir/rk4_$n/speed.csv")"
    steps=$([[ $n == "$small" ]] && echo "$ie_small" || echo "$ie_large")
    logged "$dir/implicit_$n.log" "$bench" speed --integrators implicit_euler --sizes "$n" \
      --threads 1,2 --steps "$steps" --interleave --interleave-block 5 --dt "$frame" \
      --out "$dir/implicit_$n"
    record "$r" "implicit_speedup_n$n" "$(speedup "$dir/implicit_$n/speed.csv")"
  done
  # The implicit goal's scene: the cube lowered onto the slope.
  slope=("$scene" --integrator implicit_euler --dt "$frame" --set "cube.n=$large"
    --set "terrains[0].contact.model=coulomb" --set "cube.origin=[-2.2222222,0.7,-2.2222222]"
    --threads 2 -q)
  long=$(timed "$dir/slope_30.log" "$jelly" run "${slope[@]}" --duration "$(awk -v f=$frame 'BEGIN { printf "%.16g", 30 * f }')")
  short=$(timed "$dir/slope_1.log" "$jelly" run "${slope[@]}" --duration "$frame")
  record "$r" "implicit_slope_step_ms_n$large" "$(per_step_ms "$long" "$short" 30)"
  if [[ -f $dir/slope_30.log.time ]]; then
    record "$r" "implicit_slope_peak_mb_n$large" "$(peak_mb "$dir/slope_30.log")"
  fi
  for n in "$small" "$large"; do
    fall=("$scene" --integrator xpbd --dt "$frame" --set "cube.n=$n"
      --set "terrains[0].contact.model=coulomb" --threads 2 -q)
    long=$(timed "$dir/xpbd_$n.log" "$jelly" run "${fall[@]}" --duration "$(awk -v f=$frame -v k=$frames 'BEGIN { printf "%.16g", k * f }')")
    short=$(timed "$dir/xpbd_${n}_1.log" "$jelly" run "${fall[@]}" --duration "$frame")
    record "$r" "xpbd_frame_ms_n$n" "$(per_step_ms "$long" "$short" "$frames")"
  done
  echo "round $r of $rounds done" >&2
done

# Per goal: its figures in increasing order, their median and the verdict (the median against
# the goal).
{
  if [[ $quick == 1 ]]; then
    echo "(--quick: n = $small and $large and few steps; the goals are for n = 20 and 40)"
  fi
  printf '%-44s %-8s %-8s %-30s %s\n' goal target median "figures (sorted)" met
  while IFS='|' read -r key label op target; do
    values=$(awk -F, -v k="$key" '$2 == k { print $3 }' "$figures" | sort -g | paste -sd' ')
    [[ -n $values ]] || continue
    median=$(echo "$values" | tr ' ' '\n' | awk '{ v[NR] = $1 } END {
      if (NR % 2) print v[(NR + 1) / 2]; else printf "%.4g\n", (v[NR / 2] + v[NR / 2 + 1]) / 2 }')
    met=$(awk -v m="$median" -v t="$target" -v op="$op" 'BEGIN {
      if (m == "nan") print "no"; else if (op == ">=") print (m >= t ? "yes" : "no"); else print (m <= t ? "yes" : "no") }')
    printf '%-44s %-8s %-8s %-30s %s\n' "$label" "$op $target" "$median" "$values" "$met"
  done <<EOF
rk4_speedup_n$small|rk4 n = $small: 1 thread / 2 threads|>=|1.8
rk4_speedup_n$large|rk4 n = $large: 1 thread / 2 threads|>=|1.8
implicit_speedup_n$small|implicit_euler n = $small: 1 thread / 2 threads|>=|1.8
implicit_speedup_n$large|implicit_euler n = $large: 1 thread / 2 threads|>=|1.8
implicit_slope_step_ms_n$large|implicit_euler n = $large slope, ms per step|<=|150
implicit_slope_peak_mb_n$large|implicit_euler n = $large slope, peak MB|<=|400
xpbd_frame_ms_n$small|xpbd n = $small, ms per 1/60 s frame|<=|16.7
xpbd_frame_ms_n$large|xpbd n = $large, ms per 1/60 s frame|<=|100
EOF
} | tee "$out/summary.txt"
