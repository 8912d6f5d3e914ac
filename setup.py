"""Builds the Python module jelly with CMake for `pip install .` and wheels (pyproject.toml).

Only what the module needs is configured and built (no tests, benchmarks, viewer or jelly
program). The extension jelly/_jelly*.so and the libraries it loads, jelly's components
(libjelly.so.<major>, libjelly_io.so.<major>, ...), go into the package side by side; the
extension finds them through its RPATH, $ORIGIN.
The system libraries libjelly links (HDF5, CHOLMOD, Ceres, ...) are not in the wheel: the
machine that installs it needs them (scripts/install-deps.sh), as for `cmake --install`.

Environment: JELLY_CMAKE_ARGS adds CMake arguments; JELLY_BUILD_JOBS sets the build's
parallelism (default: the number of cores). ccache is used when it is installed.
"""

import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


def version() -> str:
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(jelly VERSION ([0-9.]+)", text).group(1)


class CMakeExtension(Extension):
    def __init__(self, name: str) -> None:
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    """Configures, builds and installs (into a staging prefix) the target jelly_python, then
    copies the extension, libjelly and its Gmsh plugin into the package."""

    def build_extension(self, ext: Extension) -> None:
        build_dir = pathlib.Path(self.build_temp).resolve() / "cmake"
        stage = pathlib.Path(self.build_temp).resolve() / "stage"
        target = pathlib.Path(self.get_ext_fullpath(ext.name)).resolve().parent
        args = [
            "-DCMAKE_BUILD_TYPE=Release",
            f"-DJELLY_PYTHON_EXECUTABLE={sys.executable}",
            "-DJELLY_BUILD_TESTS=OFF", "-DJELLY_BUILD_BENCH=OFF", "-DJELLY_BUILD_VIEWER=OFF",
            "-DJELLY_BUILD_CLI=OFF", "-DJELLY_BUILD_PYTHON=ON",
            "-DJELLY_PYTHON_INSTALL_DIR=python",  # relative to the staging prefix
            "-DJELLY_PYTHON_RPATH=$ORIGIN",       # libjelly beside the extension
            "-DCMAKE_INSTALL_LIBDIR=lib",
        ]
        if shutil.which("ccache"):
            args += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache", "-DCMAKE_C_COMPILER_LAUNCHER=ccache"]
        args += shlex.split(os.environ.get("JELLY_CMAKE_ARGS", ""))
        jobs = os.environ.get("JELLY_BUILD_JOBS", str(os.cpu_count() or 1))
        subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build_dir), *args], check=True)
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "jelly_python",
                        "-j", jobs], check=True)
        if stage.exists():
            shutil.rmtree(stage)
        subprocess.run(["cmake", "--install", str(build_dir), "--prefix", str(stage)],
                       check=True, stdout=subprocess.DEVNULL)
        target.mkdir(parents=True, exist_ok=True)
        extension = next((stage / "python" / "jelly").glob("_jelly*.so"))
        shutil.copy2(extension, self.get_ext_fullpath(ext.name))
        for library in (stage / "lib").glob("libjelly*.so.*"):
            # The files the extension asks for (their SONAMEs: libjelly.so.<major>, the other
            # components' libjelly_<name>.so.<major>), as files.
            if re.fullmatch(r"libjelly(_[a-z]+)?\.so\.\d+", library.name):
                shutil.copy2(library.resolve(), target / library.name)
        # The Gmsh plugin, which libjelly loads from its own folder on first use.
        for plugin in (stage / "lib").glob("libjelly_gmsh.so"):
            shutil.copy2(plugin, target / plugin.name)


setup(
    version=version(),
    packages=["jelly"],
    package_dir={"jelly": "python/jelly"},
    package_data={"jelly": ["__init__.pyi", "py.typed", "libjelly*.so.*", "libjelly_gmsh.so"]},
    ext_modules=[CMakeExtension("jelly._jelly")],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": "build-pip"}},  # not CMake's build/
    zip_safe=False,
)
