#!/usr/bin/env bash
# Build times of the library with unity builds and precompiled headers on and off
# (docs/CONTRIBUTING.md, "Build times"): for each combination a build directory of its own; in
# each round, alternating over the combinations, a build from nothing (clean, then the targets)
# and a rebuild after touching one source of core and one of io. ccache is off
# (CCACHE_DISABLE=1, no launcher). Wall and CPU time (user + sys of make and the compilers) and
# the load average before and after go to OUT/build_times.csv; compare ratios within a round.
#
#   scripts/build_times.sh [--rounds N] [--combos "U1P1 U0P0 U1P0 U0P1"] [--jobs J]
#                          [--targets "jelly_core jelly_io"] OUT
#
# U1/U0: JELLY_UNITY_BUILD ON/OFF; P1/P0: JELLY_PRECOMPILE_HEADERS ON/OFF. The sources are
# the committed tree (git archive HEAD) copied to OUT/src, so that editing the work tree while
# it runs (an hour or more on 2 busy cores) changes nothing.
set -euo pipefail
rounds=1
combos="U1P1 U0P0 U1P0 U0P1"
jobs=2
targets="jelly_core jelly_io"
touched="core/model.cpp io/scene.cpp"
if [[ ${1:-} == --help || ${1:-} == -h ]]; then
  sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'
  exit 0
fi
while [[ $# -gt 1 ]]; do
  case $1 in
    --rounds) rounds=$2; shift 2 ;;
    --combos) combos=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --targets) targets=$2; shift 2 ;;
    *) echo "error: unknown option '$1' (allowed: --rounds, --combos, --jobs, --targets)" >&2
       exit 2 ;;
  esac
done
if [[ $# -ne 1 ]]; then
  echo "usage: scripts/build_times.sh [--rounds N] [--combos LIST] [--jobs J] [--targets LIST] OUT" >&2
  exit 2
fi
out=$1
source_dir=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out/src"
git -C "$source_dir" archive HEAD | tar -x -C "$out/src"
export CCACHE_DISABLE=1
for combo in $combos; do
  if [[ ! $combo =~ ^U[01]P[01]$ ]]; then
    echo "error: --combos: '$combo' is not U<0|1>P<0|1> (e.g. U1P0: unity on, PCH off)" >&2
    exit 2
  fi
  unity=$([[ ${combo:1:1} == 1 ]] && echo ON || echo OFF)
  pch=$([[ ${combo:3:1} == 1 ]] && echo ON || echo OFF)
  cmake -S "$out/src" -B "$out/b-$combo" -DCMAKE_BUILD_TYPE=Release -DJELLY_UNITY_BUILD=$unity \
    -DJELLY_PRECOMPILE_HEADERS=$pch -DJELLY_BUILD_TESTS=OFF -DJELLY_BUILD_BENCH=OFF \
    -DJELLY_BUILD_PYTHON=OFF -DJELLY_BUILD_VIEWER=OFF -DJELLY_BUILD_CLI=OFF >"$out/configure-$combo.log"
done
csv=$out/build_times.csv
[[ -f $csv ]] || echo "round,combo,build,wall_s,cpu_s,load_before,load_after,utc" >"$csv"
load() { cut -d' ' -f1-3 /proc/loadavg | tr ' ' '/'; }
# timed NAME LOG: runs the targets' build, appends a row.
timed() {
  local before wall user sys
  before=$(load)
  /usr/bin/time -f "%e %U %S" -o "$out/time.txt" \
    cmake --build "$out/b-$combo" -j"$jobs" --target $targets >"$2" 2>&1
  read -r wall user sys <"$out/time.txt"
  echo "$round,$combo,$1,$wall,$(awk "BEGIN { print $user + $sys }"),$before,$(load),$(date -u +%H:%M)" >>"$csv"
}
for ((round = 1; round <= rounds; round++)); do
  order=$combos
  if ((round % 2 == 0)); then order=$(echo "$combos" | tr ' ' '\n' | tac | tr '\n' ' '); fi
  for combo in $order; do
    cmake --build "$out/b-$combo" --target clean >/dev/null
    timed clean "$out/clean-$combo-$round.log"
    (cd "$out/src" && touch $touched)
    timed one_file_each "$out/touch-$combo-$round.log"
  done
done
cat "$csv"
