"""Basalt from Python: read checkpoints, field series and geometries as numpy arrays, and pack spheres.

    import basalt
    g = basalt.pack.box(size=(15, 15, 15), rmin=0.2, rmax=1.0, seed=7)   # basalt-pack box ...
    g.write("cube.h5")
    c = basalt.read_checkpoint("out/wave/ckpt_000800.h5")                 # c.positions, c.particles["velocity"]
    f = basalt.read_fields("out/wave/fields.csv")                        # f["time"], f["kinetic_energy"]
    sim = basalt.Simulation("scenes/wave.toml", geometry="cube.h5")      # a run: stages, callbacks, steering
    sim.run(until=lambda s: s.kinetic_energy() < 1e-6, every=100, steps=10_000)

docs/python.md documents the package. ``import basalt`` needs only the standard library: numpy, h5py and the
compiled core (basalt._core) are loaded by the first function that needs them, so a missing h5py fails
read_checkpoint with a message saying so, never the import.
"""

import importlib

from ._errors import FormatError, InputError, PackError, RunError
from ._version import __version__

# Public name -> the submodule defining it; loaded on first use (PEP 562).
_LAZY = {
    "Geometry": "geometry",
    "read_geometry": "geometry",
    "Checkpoint": "checkpoint",
    "read_checkpoint": "checkpoint",
    "read_checkpoints": "checkpoint",
    "read_fields": "fields",
    "Simulation": "simulation",
}
_SUBMODULES = ("pack", "geometry", "checkpoint", "fields", "simulation")

__all__ = ["__version__", "FormatError", "PackError", "InputError", "RunError", "pack", *_LAZY]


def __getattr__(name):
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    elif name in _SUBMODULES:
        value = importlib.import_module(f".{name}", __name__)
    else:
        raise AttributeError(f"module 'basalt' has no attribute '{name}'")
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__) | set(_SUBMODULES))
