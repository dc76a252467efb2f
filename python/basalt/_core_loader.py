"""Loads the compiled core (basalt._core) on first use, with a message that says what to do when it is
missing: the pure-Python parts (read_checkpoint's data, read_fields) work without it."""

_core = None


def core():
    global _core
    if _core is None:
        try:
            from . import _core as module
        except ImportError as e:
            raise ImportError(
                f"basalt's compiled core (basalt._core) cannot be loaded: {e}. It is built with Basalt "
                "(cmake --build build; BASALT_WITH_PYTHON=ON needs pybind11-dev and python3-dev) into "
                "build/python/basalt, for the Python that CMake found (Debian's /usr/bin/python3 by default); "
                "docs/python.md") from e
        _core = module
    return _core
