"""ESyS-Particle scripts on Basalt (docs/esys.md): `python3 -m basalt.esys script.py [args]` (or basalt-esys)
runs a script written against esys.lsm with Basalt's stand-in modules, which live in a private folder
(_shim/esys) put first on sys.path in that process only: `import esys` anywhere else finds a real
ESyS-Particle, or nothing.

    from basalt.esys import run_script
    run_script("bingle.py", ["--steps", "100"])        # as python3 -m basalt.esys bingle.py --steps 100
"""

import builtins
import io
import os
import runpy
import sys

from .errors import NotSupportedError

SHIM_ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "_shim")

__all__ = ["NotSupportedError", "run_script", "activate", "world", "SHIM_ROOT"]


def activate():
    """Makes `import esys` (esys.lsm, esys.lsm.util, esys.lsm.geometry) resolve to Basalt's shim in this
    process: the shim's folder goes first on sys.path, and esys modules imported before are dropped."""
    for name in [m for m in sys.modules if m == "esys" or m.startswith("esys.")]:
        del sys.modules[name]
    if SHIM_ROOT in sys.path:
        sys.path.remove(SHIM_ROOT)
    sys.path.insert(0, SHIM_ROOT)


def world():
    """(rank, size) of this process in mpirun's world, from the launcher's environment (Open MPI's
    OMPI_COMM_WORLD_RANK/SIZE, MPICH's PMI_RANK/SIZE), read before MPI starts; (0, 1) without mpirun."""
    for rank, size in (("OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE"), ("PMI_RANK", "PMI_SIZE")):
        if rank in os.environ and size in os.environ:
            return int(os.environ[rank]), int(os.environ[size])
    return 0, 1


class _RankFiles:
    """The script's own files under mpirun, where every rank runs it (ESyS runs it once, on its master): rank 0
    writes them, the other ranks write to os.devnull; a file the script wrote is read (open for reading,
    readGeometry) by every rank once all have come to that read (a barrier: the script makes the same calls on
    every rank), so that none reads it while rank 0 is still writing it."""

    def __init__(self, rank):
        self.rank = rank
        self.written = set()
        self.open = builtins.open

    def __call__(self, file, mode="r", *args, **kwargs):
        if isinstance(file, int):  # a file descriptor: the caller's own
            return self.open(file, mode, *args, **kwargs)
        key = os.path.abspath(os.fspath(file))
        if any(c in mode for c in "wax+"):
            self.written.add(key)
            if self.rank != 0:
                # the file exists afterwards on every rank, as after rank 0's open (numpy.savetxt creates a file,
                # then opens it again and finds it): made if missing, never truncated, rank 0 alone writes it
                if "x" not in mode:
                    self.open(file, "ab").close()
                return self.open(os.devnull, mode.replace("x", "w"), *args, **kwargs)
        else:
            self.before_read(key)
        return self.open(file, mode, *args, **kwargs)

    def before_read(self, path):
        key = os.path.abspath(os.fspath(path))
        if key in self.written:
            self.written.discard(key)  # (written again later: waited for again)
            from .._core_loader import core
            core().world_barrier()


_rank_files = None


def before_read(path):
    """Called by the front end before it reads a file the script may have written (readGeometry)."""
    if _rank_files is not None:
        _rank_files.before_read(path)


def run_script(path, args=()):
    """Runs the ESyS script `path` as __main__ with sys.argv = [path, *args], its folder on sys.path (after
    the shim), as `python3 path` would. Under mpirun every rank runs it (Basalt's calls are collective); the
    script's prints appear once: ranks other than 0 print to os.devnull (their stderr is kept), and write the
    script's own files there too (_RankFiles)."""
    global _rank_files
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"basalt.esys: no script {path!r}")
    sys.argv = [path, *args]
    activate()
    sys.path.insert(1, os.path.dirname(os.path.abspath(path)))
    rank, size = world()
    if size == 1:
        return runpy.run_path(path, run_name="__main__")
    _rank_files = _RankFiles(rank)
    stdout = sys.stdout
    builtins.open = io.open = _rank_files
    if rank != 0:
        sys.stdout = _rank_files.open(os.devnull, "w")
    try:
        return runpy.run_path(path, run_name="__main__")
    finally:
        builtins.open = io.open = _rank_files.open
        _rank_files = None
        if rank != 0:
            sys.stdout.close()
            sys.stdout = stdout
