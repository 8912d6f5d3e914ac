#!/usr/bin/env bash
# -DJELLY_BUILD_VIEWER=OFF is honoured: a configure of the project with it (no tests, benchmarks
# or Python module: a configure only, no build) has the viewer's core (the exports of `jelly
# export`) and the jelly program, and neither the OpenGL parts, the window nor the component
# viewer; the configure says so. The configure with it on is this build's own (the install
# test checks the component there).
# Usage: viewer_option_test.sh CMAKE SOURCE_DIR
set -euo pipefail
cmake=$1 source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$cmake" -S "$source_dir" -B "$work/build" -DJELLY_BUILD_VIEWER=OFF -DJELLY_BUILD_TESTS=OFF \
  -DJELLY_BUILD_BENCH=OFF -DJELLY_BUILD_PYTHON=OFF >"$work/configure.log" 2>&1 ||
  { cat "$work/configure.log"; exit 1; }
grep -q 'viewer: JELLY_BUILD_VIEWER is off' "$work/configure.log" ||
  { cat "$work/configure.log"; echo "the configure does not say the viewer is off"; exit 1; }
targets=$("$cmake" --build "$work/build" --target help | sed -n 's/^\.\.\. \([^ ]*\).*/\1/p')
for wanted in jelly_viewer_core jelly_cli; do
  echo "$targets" | grep -qx "$wanted" || { echo "no target $wanted with the viewer off"; exit 1; }
done
for unwanted in jelly_viewer_gl jelly_viewer_window jelly_viewer jelly_imgui_backends; do
  if echo "$targets" | grep -qx "$unwanted"; then
    echo "target $unwanted with JELLY_BUILD_VIEWER=OFF"; exit 1
  fi
done
echo "viewer_option_test: ok"
