"""ESyS-Particle scripts on Basalt (docs/esys.md): `python3 -m basalt.esys script.py [args]` (or basalt-esys)
runs a script written against esys.lsm with Basalt's stand-in modules, which live in a private folder
(_shim/esys) put first on sys.path in that process only: `import esys` anywhere else finds a real
ESyS-Particle, or nothing.

    from basalt.esys import run_script
    run_script("bingle.py", ["--steps", "100"])        # as python3 -m basalt.esys bingle.py --steps 100
"""

import os
import runpy
import sys

from .errors import NotSupportedError

SHIM_ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "_shim")

__all__ = ["NotSupportedError", "run_script", "activate", "SHIM_ROOT"]


def activate():
    """Makes `import esys` (esys.lsm, esys.lsm.util, esys.lsm.geometry) resolve to Basalt's shim in this
    process: the shim's folder goes first on sys.path, and esys modules imported before are dropped."""
    for name in [m for m in sys.modules if m == "esys" or m.startswith("esys.")]:
        del sys.modules[name]
    if SHIM_ROOT in sys.path:
        sys.path.remove(SHIM_ROOT)
    sys.path.insert(0, SHIM_ROOT)


def run_script(path, args=()):
    """Runs the ESyS script `path` as __main__ with sys.argv = [path, *args], its folder on sys.path (after
    the shim), as `python3 path` would."""
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"basalt.esys: no script {path!r}")
    sys.argv = [path, *args]
    activate()
    sys.path.insert(1, os.path.dirname(os.path.abspath(path)))
    return runpy.run_path(path, run_name="__main__")
