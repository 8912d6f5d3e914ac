#!/usr/bin/env bash
# Installs the built jelly into a temporary prefix, then configures, builds and runs the
# out-of-tree consumer (examples/consumer) against it: the package works as README says.
# Usage: install_consumer_test.sh CMAKE BUILD_DIR SOURCE_DIR
set -euo pipefail
cmake=$1 build_dir=$2 source_dir=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix

"$cmake" --install "$build_dir" --prefix "$prefix" >"$work/install.log"

for f in include/jelly/jelly.hpp include/jelly/io/scene.hpp include/jelly/geometry/cube.hpp \
         bin/jelly share/jelly/scenes/seed_slope.json; do
  [ -e "$prefix/$f" ] || { echo "missing from the install: $f"; exit 1; }
done
config=$(find "$prefix" -name jellyConfig.cmake)
[ -n "$config" ] && [ -e "$(dirname "$config")/jellyConfigVersion.cmake" ] ||
  { echo "missing from the install: jellyConfig.cmake / jellyConfigVersion.cmake"; exit 1; }
# The component viewer, when this build has it (viewer/CMakeLists.txt: JELLY_BUILD_VIEWER, a
# shared build, OpenGL, EGL, stb, GLFW and Dear ImGui found): its library and its headers, every
# header of viewer/ but those under detail/.
viewer=FALSE
if [ -n "$(find "$prefix" -name 'libjelly_viewer.so')" ]; then
  viewer=TRUE
  installed_viewer=$(cd "$prefix/include/jelly" && find viewer -type f 2>/dev/null | sort)
  source_viewer=$(cd "$source_dir" && find viewer -maxdepth 1 -name '*.hpp' | sort)
  if [ "$installed_viewer" != "$source_viewer" ]; then
    echo "the installed viewer headers differ from viewer/*.hpp (< installed, > source):"
    diff <(echo "$installed_viewer") <(echo "$source_viewer") || true
    exit 1
  fi
fi
# The installed headers are the public ones (cmake/public_headers.txt) and no other.
installed=$(cd "$prefix/include/jelly" && find . -type f -not -path './viewer/*' |
            sed 's|^\./||' | sort)
public=$( (sed -n 's/^\([a-z][^ ]*\).*/\1/p' "$source_dir/cmake/public_headers.txt"
           echo jelly.hpp; echo version.hpp) | sort)
if [ "$installed" != "$public" ]; then
  echo "the installed headers differ from cmake/public_headers.txt (< installed, > listed):"
  diff <(echo "$installed") <(echo "$public") || true
  exit 1
fi
# The Gmsh plugin sits beside libjelly, where libjelly looks for it.
[ -e "$(dirname "$(find "$prefix" -name 'libjelly.so' | head -1)")/libjelly_gmsh.so" ] ||
  { echo "missing from the install: libjelly_gmsh.so beside libjelly.so"; exit 1; }
"$prefix/bin/jelly" list | grep -q '^mesher *gmsh *fills'

"$prefix/bin/jelly" list | grep -q '^integrator rk4 '

"$cmake" -S "$source_dir/examples/consumer" -B "$work/build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" >"$work/configure.log" || { cat "$work/configure.log"; exit 1; }
"$cmake" --build "$work/build" >"$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }

out=$("$work/build/consumer" "$prefix/share/jelly/scenes/seed_slope.json" 0.1)
echo "$out"
# 0.1 s of free fall from the seed pose: the centre of mass drops from 8.7778 by g t^2 / 2.
echo "$out" | grep -q '^completed at t = 0.1 s after 100 steps'
echo "$out" | grep -q '^centre of mass: -0.2222.* 8.72[78]'
# A force and a terrain of one's own (examples/consumer/vortex_force.hpp, ripple_floor.hpp):
# the vortex turns the falling cube about the vertical axis (its height as in free fall) and
# gives its Jacobian, so implicit_euler has no note; the rippled floor holds the dropped cube.
out=$("$work/build/consumer" "$prefix/share/jelly/scenes/seed_slope.json" 1 --vortex 3)
echo "$out"
echo "$out" | grep -q '^completed at t = 1 s'
echo "$out" | grep -q '^centre of mass: .* 3.87[78]'
if echo "$out" | grep -q '^centre of mass: -0.2222 .* -0.2222$'; then
  echo "the vortex did not turn the cube"; exit 1
fi
out=$("$work/build/consumer" "$prefix/share/jelly/scenes/drop_coulomb.json" 2 --ripple 0.3)
echo "$out"
echo "$out" | grep -q '^completed at t = 2 s'
echo "$out" | awk '/^centre of mass:/ { exit !($5 > 0.5) }'

# The core alone (examples/consumer_core: find_package(jelly COMPONENTS core), jelly::core): it
# builds, runs the seed cube on the slope, has no component's integrators, and loads none of
# HDF5, SUNDIALS, Ceres or assimp; at most 25 shared libraries (docs/CONTRIBUTING.md,
# "Components").
"$cmake" -S "$source_dir/examples/consumer_core" -B "$work/build_core" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" >"$work/configure_core.log" ||
  { cat "$work/configure_core.log"; exit 1; }
"$cmake" --build "$work/build_core" >"$work/build_core.log" 2>&1 ||
  { cat "$work/build_core.log"; exit 1; }
out=$("$work/build_core/consumer_core" 0.5)
echo "$out"
echo "$out" | grep -q '^components: core$'
echo "$out" | grep -q '^integrators: .*implicit_euler'
if echo "$out" | grep -q arkode; then echo "the core alone names ARKODE's integrators"; exit 1; fi
echo "$out" | grep -q '^completed at t = 0.5 s after 30 steps'
libraries=$(ldd "$work/build_core/consumer_core")
count=$(echo "$libraries" | wc -l)
echo "consumer_core: $count shared libraries (ldd)"
if echo "$libraries" | grep -E 'libhdf5|libsundials|libceres|libassimp|libjelly_'; then
  echo "consumer_core loads a library of another component"; exit 1
fi
[ "$count" -le 25 ] || { echo "$libraries"; echo "consumer_core: more than 25 libraries"; exit 1; }

# find_package's COMPONENTS: jelly_<component>_FOUND for each, a required unknown one fails with
# a message naming it, an optional one does not.
mkdir -p "$work/components"
cat >"$work/components/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.20)
project(jelly_components LANGUAGES CXX)
find_package(jelly CONFIG REQUIRED COMPONENTS core io OPTIONAL_COMPONENTS arkode viewer)
message(STATUS "found: core=${jelly_core_FOUND} io=${jelly_io_FOUND} viewer=${jelly_viewer_FOUND}")
CMAKE
"$cmake" -S "$work/components" -B "$work/components/build" -DCMAKE_PREFIX_PATH="$prefix" \
  >"$work/components.log" 2>&1 || { cat "$work/components.log"; exit 1; }
grep -q "found: core=TRUE io=TRUE viewer=$viewer" "$work/components.log" ||
  { cat "$work/components.log"; exit 1; }
sed -i 's/OPTIONAL_COMPONENTS arkode viewer/teapot/' "$work/components/CMakeLists.txt"
rm -rf "$work/components/build"
if "$cmake" -S "$work/components" -B "$work/components/build" -DCMAKE_PREFIX_PATH="$prefix" \
     >"$work/components.log" 2>&1; then
  echo "find_package(jelly REQUIRED COMPONENTS teapot) succeeded"; exit 1
fi
grep -q 'no component "teapot"' "$work/components.log" || { cat "$work/components.log"; exit 1; }

# The component viewer from outside (examples/consumer_viewer: find_package(jelly COMPONENTS
# viewer), jelly::viewer): the seed jelly drawn offscreen into a PNG, in the picture's middle.
# Without it, asking for it fails naming why.
if [ "$viewer" = TRUE ]; then
  "$cmake" -S "$source_dir/examples/consumer_viewer" -B "$work/build_viewer" \
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" >"$work/configure_viewer.log" ||
    { cat "$work/configure_viewer.log"; exit 1; }
  "$cmake" --build "$work/build_viewer" >"$work/build_viewer.log" 2>&1 ||
    { cat "$work/build_viewer.log"; exit 1; }
  "$prefix/bin/jelly" list | grep -q '^component  viewer ' ||
    { echo "jelly list names no component viewer"; exit 1; }
  out=$("$work/build_viewer/consumer_viewer" "$prefix/share/jelly/scenes/seed_slope.json" \
        "$work/viewer.png") || { echo "$out"; exit 1; }
  echo "$out"
  echo "$out" | grep -q '^components: core .*viewer'
  [ -s "$work/viewer.png" ] || { echo "consumer_viewer wrote no PNG"; exit 1; }
  echo "$out" | awk '/^red share/ { exit !($3 > 0.01) }' ||
    { echo "the jelly is not in consumer_viewer's picture"; exit 1; }
else
  sed -i 's/teapot/viewer/' "$work/components/CMakeLists.txt"
  rm -rf "$work/components/build"
  if "$cmake" -S "$work/components" -B "$work/components/build" -DCMAKE_PREFIX_PATH="$prefix" \
       >"$work/components.log" 2>&1; then
    echo "find_package(jelly REQUIRED COMPONENTS viewer) succeeded without it"; exit 1
  fi
  grep -q 'built without the component viewer' "$work/components.log" ||
    { cat "$work/components.log"; exit 1; }
fi
echo "install_consumer_test: ok"
