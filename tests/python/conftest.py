"""Fixtures of the pytest suites of the Python module `jelly` (run by ctest, tests/python/
CMakeLists.txt, with PYTHONPATH=build/python, JELLY_CLI and JELLY_SOURCE_DIR set)."""

import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("JELLY_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))
SCENES = SOURCE_DIR / "scenes"


@pytest.fixture
def scenes() -> pathlib.Path:
    return SCENES


@pytest.fixture
def jelly_cli() -> str:
    cli = os.environ.get("JELLY_CLI")
    if not cli or not os.path.exists(cli):
        pytest.fail("JELLY_CLI (the jelly program) is not set: run the tests with ctest")
    return cli


@pytest.fixture
def run_cli(jelly_cli):
    def run(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([jelly_cli, *map(str, args)], capture_output=True, text=True,
                              check=False)
    return run
