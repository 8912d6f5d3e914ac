#!/usr/bin/env bash
# Installs, with apt, the Debian packages jelly needs that are missing. Idempotent: a machine
# that already has everything is left untouched and nothing is downloaded.
#   install-deps.sh           what building, running and `make demo` need
#   install-deps.sh --tests   and what only tests need (`make test` and CI pass it), which
#                             includes what --docs installs (the site's tests)
#   install-deps.sh --docs    and what `make docs` needs: MkDocs, Doxygen, Chromium
set -euo pipefail

packages=(
  build-essential cmake make pkg-config git
  libeigen3-dev libsuitesparse-dev libopenblas-dev libsundials-dev libhdf5-dev hdf5-tools
  libceres-dev libgtest-dev libgmock-dev googletest libbenchmark-dev nlohmann-json3-dev libcli11-dev
  python3-h5py python3-matplotlib python3-numpy ffmpeg clang-format ccache
  # scripts/scale_goals.sh: a run's peak memory (/usr/bin/time)
  time
  # meshes: reading OBJ/STL/PLY (assimp), tetrahedral meshes and `jelly mesh` (Gmsh)
  libassimp-dev libgmsh-dev
  # scripts/make_assets.py (the meshes under assets/) and its test: Gmsh's Python API
  python3-gmsh
  # the viewer (jelly view / render): OpenGL through GLVND, Mesa's EGL and software drivers
  # (llvmpipe), GLFW, Dear ImGui with its backends, stb for PNG; Xvfb for its tests (and for the
  # test jelly_paraview's screenshot)
  libglfw3-dev libimgui-dev libstb-dev libopengl-dev libegl-dev libegl-mesa0 libglx-mesa0
  libgl1-mesa-dri xvfb xauth
  # the Python module jelly (python/): bindings, its tests, sweeps on Dask
  pybind11-dev python3-pybind11 python3-dev python3-pytest python3-distributed python3-pandas
  # sparse Jacobians of forces written in Python (jelly.Force.jacobians)
  python3-scipy
  # the wheel test (tests/python/wheel_test.sh): python3 -m build
  python3-build python3-venv
  # jelly.dlpack: arrays handed to torch/JAX without copies (DLPack's header only)
  libdlpack-dev
  # `jelly export --gltf`: tinygltf builds and writes the glTF 2.0 file (its header and a small
  # shared library; it reads JSON with nlohmann-json3-dev and images with libstb-dev, both above)
  libtinygltf-dev
)
# `make docs` (scripts/build_docs.py): the site (mkdocs, its material theme), the C++ API
# reference (doxygen), and the test that opens pages in headless Chromium (chromium, about
# 100 MB to download).
docs_packages=(mkdocs mkdocs-material doxygen chromium)
if [ "${1:-}" = "--docs" ]; then
  packages+=("${docs_packages[@]}")
elif [ "${1:-}" = "--tests" ]; then
  packages+=("${docs_packages[@]}")
  # The test jelly_paraview (tests/io/paraview_test.py; it skips without them): ParaView and its
  # pvpython (python3-paraview, only recommended by paraview). About 120 MB to download.
  packages+=(paraview python3-paraview)
  # `make test-sanitize` (CI runs it): clang with AddressSanitizer, UndefinedBehaviorSanitizer and
  # libFuzzer (libclang-rt-dev), OpenMP for clang (libomp-dev), llvm-symbolizer for the reports'
  # stack traces (llvm)
  packages+=(clang libclang-rt-dev libomp-dev llvm)
  # jelly-bench-bullet (bench/bullet_peer.cpp, built only when Bullet is found): the frame budget
  # against Bullet's classic soft body (docs/performance.md). About 10 MB to download.
  packages+=(libbullet-dev)
elif [ $# -gt 0 ]; then
  echo "usage: $0 [--tests | --docs]" >&2
  exit 2
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
