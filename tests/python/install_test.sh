#!/usr/bin/env bash
# Installs the built jelly into a temporary prefix and imports the Python module from the
# prefix's site-packages, away from the build tree: `cmake --install` works as README says.
# Usage: install_test.sh CMAKE BUILD_DIR PYTHON SITE_PACKAGES_RELATIVE_TO_PREFIX
set -euo pipefail
cmake=$1 build_dir=$2 python=$3 site=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
"$cmake" --install "$build_dir" --prefix "$prefix" >"$work/install.log"
for f in __init__.py __init__.pyi _rollout.py _scene.py _sweep.py py.typed; do
  [ -e "$prefix/$site/jelly/$f" ] || { echo "missing from the install: $site/jelly/$f"; exit 1; }
done
ls "$prefix/$site/jelly/"_jelly*.so >/dev/null
cd "$work"
PYTHONPATH="$prefix/$site" PYTHONDONTWRITEBYTECODE=1 "$python" - "$prefix" <<'PY'
import os, sys
import jelly
prefix = sys.argv[1]
assert jelly.__file__.startswith(prefix), jelly.__file__
scene = jelly.load_scene(os.path.join(prefix, "share/jelly/scenes/seed_slope.json"),
                         {"duration": 0.1})
sim = jelly.Simulator(scene)
report = sim.run_until(scene.duration)
print(report.brief(), sim.center_of_mass())
assert report.ok and abs(sim.center_of_mass()[1] - (79 / 9 - 9.8 * 0.1 ** 2 / 2)) < 1e-3
PY
echo "install_test: ok ($site)"
