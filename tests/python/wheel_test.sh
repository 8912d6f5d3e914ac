#!/usr/bin/env bash
# pip install and wheels (pyproject.toml, setup.py) from a copy of the source tree in a temporary
# directory: `python3 -m build --wheel --no-isolation` (or `pip wheel --no-build-isolation` when
# python3-build is missing) makes a wheel holding the extension and libjelly.so.<major> side by
# side (RPATH $ORIGIN); it installs into a fresh venv (--system-site-packages, for NumPy) without
# an index, imports from another directory, runs, shows in `pip show` and uninstalls.
# Usage: wheel_test.sh SOURCE_DIR PYTHON
set -euo pipefail
source_dir=$1 python=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir "$work/src"
# The working tree's files as git sees them (committed or not), without build outputs.
git -C "$source_dir" ls-files -z --cached --others --exclude-standard |
  (cd "$source_dir" && xargs -0 tar -cf - --no-recursion) | tar -xf - -C "$work/src"
cd "$work/src"
export CCACHE_BASEDIR=$work/src  # relative paths: hits from any earlier copy's build
if "$python" -c "import build" 2>/dev/null; then
  "$python" -m build --wheel --no-isolation --outdir "$work/dist" >"$work/build.log" 2>&1 ||
    { tail -40 "$work/build.log"; exit 1; }
else
  "$python" -m pip wheel --no-build-isolation --no-deps . -w "$work/dist" >"$work/build.log" 2>&1 ||
    { tail -40 "$work/build.log"; exit 1; }
fi
wheel=$(ls "$work"/dist/jelly-*.whl)
"$python" - "$wheel" <<'PY'
import sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
for expected in ("jelly/__init__.py", "jelly/__init__.pyi", "jelly/py.typed", "jelly/libjelly.so.0",
                 "jelly/libjelly_io.so.0", "jelly/libjelly_gmsh.so"):
    assert expected in names, (expected, names)
assert any(n.startswith("jelly/_jelly") and n.endswith(".so") for n in names), names
PY
"$python" -m venv --system-site-packages "$work/venv"
"$work/venv/bin/pip" install --no-index --no-deps "$wheel" >"$work/install.log"
site=$("$work/venv/bin/python" -c "import sysconfig; print(sysconfig.get_path('platlib'))")
dynamic=$(readelf -d "$site"/jelly/_jelly*.so)
grep -q 'R.*PATH.*\[\$ORIGIN\]' <<<"$dynamic" ||
  { echo "the extension's RPATH is not \$ORIGIN: $dynamic"; exit 1; }
mkdir "$work/elsewhere" && cd "$work/elsewhere"
PYTHONDONTWRITEBYTECODE=1 "$work/venv/bin/python" - "$site" "$source_dir" <<'PY'
import os, sys
import jelly
assert jelly.__file__.startswith(sys.argv[1]), jelly.__file__
scene = jelly.load_scene(os.path.join(sys.argv[2], "scenes", "seed_slope.json"), {"duration": 0.1})
sim = jelly.Simulator(scene)
report = sim.run_until(scene.duration)
assert report.ok and abs(sim.center_of_mass()[1] - (79 / 9 - 9.8 * 0.1 ** 2 / 2)) < 1e-3
print(report.brief())
PY
shown=$("$work/venv/bin/pip" show jelly)
grep -q '^Name: jelly$' <<<"$shown" || { echo "pip show jelly: $shown"; exit 1; }
"$work/venv/bin/pip" uninstall -y jelly >/dev/null
if "$work/venv/bin/python" -c "import jelly" 2>/dev/null; then
  echo "jelly still imports after pip uninstall"; exit 1
fi
[ ! -e "$site/jelly" ] || { echo "pip uninstall left $site/jelly"; exit 1; }
echo "wheel_test: ok ($(basename "$wheel"))"
