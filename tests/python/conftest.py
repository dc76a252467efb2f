"""Shared set-up of the Python package's tests (ctest -L python; tests/python/CMakeLists.txt).

ctest runs them with PYTHONPATH=<build>/python and BASALT_BIN=<build>/bin; by hand:
    PYTHONPATH=build/python BASALT_BIN=build/bin /usr/bin/python3 -m pytest tests/python
"""

import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(os.environ.get("BASALT_SOURCE_DIR") or pathlib.Path(__file__).resolve().parents[2])
BIN = pathlib.Path(os.environ.get("BASALT_BIN") or ROOT / "build" / "bin")
CUBE = ROOT / "tests" / "data" / "cube1.geo"

sys.path.insert(0, str(ROOT / "tools"))
import basalt_tools  # noqa: E402  (the tools' shared module: Open MPI's settings, basalt-run's command line)


def run(cmd, check=True, **kw):
    """A command of the build with Open MPI's settings (scripts/mpi-env.sh); fails the test with its output."""
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, env=basalt_tools.mpi_env(), **kw)
    if check and p.returncode != 0:
        pytest.fail(f"{' '.join(map(str, cmd))} exited {p.returncode}:\n{p.stdout}\n{p.stderr}")
    return p


@pytest.fixture(scope="session")
def bin_dir():
    for exe in ("basalt-pack", "basalt-run"):
        if not (BIN / exe).exists():
            pytest.fail(f"{BIN / exe} is missing: build it (cmake --build build), or set BASALT_BIN")
    return BIN
