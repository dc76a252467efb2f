"""basalt-pack from Python: box, cylinder, sphere and mesh pack a volume with bonded spheres and return a
basalt.Geometry (write it with .write("cube.h5") or .write("cube.geo")).

    g = basalt.pack.box(size=(15, 15, 15), rmin=0.2, rmax=1.0, seed=7)
    # the same spheres and bonds as: basalt-pack box --size 15,15,15 --rmin 0.2 --rmax 1.0 --seed 7 -o cube.h5

The keywords are basalt-pack's options with underscores (--bond-tolerance: bond_tolerance) and its defaults
(docs/packer.md). The request goes through basalt-pack's own code (basalt._core), so the same arguments give
the same spheres and bonds, bit for bit, and an impossible request raises basalt.PackError (a ValueError)
with basalt-pack's message, which names the command-line option (``--bond-tolerance must be >= 0, got -1``).
Vectors (size, origin, centre) are three numbers or basalt-pack's text "15,15,15"; tag_layer is one or a list
of "FACE:THICKNESS:TAG" texts or (face, thickness, tag) tuples; threads=None uses every core (the result does
not depend on it). Other Python threads run while it packs; Ctrl-C does not stop a pack.
"""

import inspect
import operator
import os
import time
import warnings

from . import _core_loader
from ._version import __version__
from .geometry import Geometry

_REQUIRED = inspect.Parameter.empty

# The options every shape takes, in basalt-pack's order, with its defaults (tests/python/test_pack.py checks
# them against the C++ request's).
_COMMON = (
    ("rmin", _REQUIRED),
    ("rmax", _REQUIRED),
    ("seed", 1),
    ("exponent", None),
    ("target_fraction", 0.55),
    ("fill", False),
    ("bond_tolerance", 1e-5),
    ("no_bonds", False),
    ("lattice", False),
    ("bond_tag", 0),
    ("overlap_tolerance", 1e-6),
    ("tag_layer", ()),
    ("seed_fraction", 0.2),
    ("bins", 16),
    ("threads", None),
    ("max_spheres", 1e7),
    ("allow_large", False),
    ("allow_low_fraction", False),
    ("record_time", False),
    ("output", None),
)
# Options that change nothing in the file, left out of its command_line (as basalt-pack leaves out -o, -q and
# --threads).
_NOT_RECORDED = {"threads", "output"}


def _vec3(value):
    """basalt-pack's "X,Y,Z" text of a vector: a text as given, numbers in their shortest exact form."""
    if isinstance(value, str):
        return value
    return ",".join(repr(float(v)) for v in value)


def _seed(value):
    if isinstance(value, bool):
        raise TypeError("seed: a whole number, not a bool")
    return value if isinstance(value, str) else str(int(value)) if isinstance(value, int) else str(value)


def _tag_layers(value):
    def number(x):  # 2 -> "2", 0.3 -> "0.3", numpy's scalars alike; a text as given
        return x if isinstance(x, str) else str(operator.index(x)) if hasattr(x, "__index__") else repr(float(x))

    def one(t):
        if isinstance(t, str):
            return t
        face, thickness, tag = t
        return f"{face}:{number(thickness)}:{number(tag)}"

    if isinstance(value, str) or (isinstance(value, tuple) and len(value) == 3 and isinstance(value[0], str)
                                  and not isinstance(value[1], str)):
        return [one(value)]
    return [one(t) for t in value]


_FLOATS = ("rmin", "rmax", "target_fraction", "bond_tolerance", "overlap_tolerance", "seed_fraction", "max_spheres")
_INTS = ("bond_tag", "bins")
_BOOLS = ("fill", "no_bonds", "lattice", "allow_large", "allow_low_fraction")


def _typed(name, value, kind):
    """A keyword's value as the C++ request takes it; a TypeError naming the keyword otherwise."""
    try:
        if kind is int:
            return operator.index(value)  # 16, not 16.0
        return float(value)
    except (TypeError, ValueError):
        what = "a whole number" if kind is int else "a number"
        raise TypeError(f"{name}={value!r}: {what} expected") from None


def _pack(shape, call, volume, options):
    core = _core_loader.core()
    o = dict(options)
    output = o.pop("output")
    record_time = o.pop("record_time")
    threads, exponent = o.pop("threads"), o.pop("exponent")
    for name in _FLOATS:
        o[name] = _typed(name, o[name], float)
    for name in _INTS:
        o[name] = _typed(name, o[name], int)
    for name in _BOOLS:
        o[name] = bool(o[name])
    o["seed"] = _seed(o["seed"])
    o["tag_layer"] = _tag_layers(o["tag_layer"])
    args = dict(size="", origin="0,0,0", centre="0,0,0", radius=0.0, height=0.0, mesh_file="")
    args.update(volume)
    start = time.perf_counter()
    d, stats = core.pack(shape=shape, exponent=None if exponent is None else _typed("exponent", exponent, float),
                         threads=None if threads is None else _typed("threads", threads, int),
                         output="" if output is None else os.fspath(output), **args, **o)
    seconds = time.perf_counter() - start
    g = Geometry._from_core(d)
    g.pack_stats = stats
    g.attrs["creator"] = f"{core.pack_creator} (Python basalt.pack {__version__})"
    g.attrs["command_line"] = call
    if record_time:
        g.statistics["pack_seconds"] = [seconds]
        g.attrs["created"] = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
    if stats["far_below"]:
        warnings.warn(f"{stats['note']} (written as allow_low_fraction asks)", stacklevel=3)
    if output is not None:
        g.write(output)
    return g


def _shape(shape, volume_params, doc):
    """A packing function with an explicit signature: the shape's parameters (the first may be given by
    position), then the options of _COMMON, keywords only."""
    kinds = [inspect.Parameter.POSITIONAL_OR_KEYWORD] + [inspect.Parameter.KEYWORD_ONLY] * len(volume_params)
    params = [inspect.Parameter(n, k, default=d) for (n, d), k in zip(volume_params, kinds)]
    params += [inspect.Parameter(n, inspect.Parameter.KEYWORD_ONLY, default=d) for n, d in _COMMON]
    signature = inspect.Signature(params)

    def pack(*args, **kwargs):
        if shape == "sphere" and "center" in kwargs:  # basalt-pack's --center
            if "centre" in kwargs:
                raise TypeError("basalt.pack.sphere(): give centre or center, not both")
            kwargs["centre"] = kwargs.pop("center")
        given = signature.bind(*args, **kwargs)
        call = f"basalt.pack.{shape}(" + ", ".join(
            f"{k}={v!r}" for k, v in given.arguments.items() if k not in _NOT_RECORDED) + ")"
        given.apply_defaults()
        options = dict(given.arguments)
        volume = {}
        for name, _ in volume_params:
            value = options.pop(name)
            if name in ("size", "origin", "centre"):
                volume[name] = _vec3(value)
            elif name == "file":
                volume["mesh_file"] = str(value)
            else:
                volume[name] = _typed(name, value, float)
        return _pack(shape, call, volume, options)

    pack.__name__ = pack.__qualname__ = shape
    pack.__module__ = __name__
    pack.__signature__ = signature
    pack.__doc__ = doc + _OPTIONS_DOC
    return pack


_OPTIONS_DOC = """

Options (basalt-pack's, docs/packer.md): rmin, rmax (required: 0 < rmin <= rmax); seed (0 .. 2^64-1: the same
seed and options give the same spheres); exponent (follow the power law N(>r) ~ r^-exponent instead of filling
as densely as possible), target_fraction, fill; bond_tolerance (bond pairs whose gap is <= this), no_bonds,
bond_tag; lattice (a loose cubic lattice for granular flow); overlap_tolerance; tag_layer ("FACE:THICKNESS:TAG"
or (face, thickness, tag), one or a list); seed_fraction; bins (radius histogram); threads (None: every core);
max_spheres, allow_large; allow_low_fraction; record_time (store the pack time and date); output (also write
the geometry there, .h5 or .geo, checked before packing).

Returns a basalt.Geometry whose pack_stats holds what basalt-pack prints (particles, solid_fraction, bonds,
bonds_per_particle, mean_coordination, fitted_exponent, histogram, largest overlaps, note). Raises
basalt.PackError with basalt-pack's message for an impossible request."""

box = _shape("box", [("size", _REQUIRED), ("origin", (0, 0, 0))],
             "Packs an axis-aligned box from origin to origin + size (basalt-pack box).")
cylinder = _shape("cylinder", [("radius", _REQUIRED), ("height", _REQUIRED), ("origin", (0, 0, 0))],
                  "Packs a cylinder along z whose base is centred at origin (basalt-pack cylinder).")
sphere = _shape("sphere", [("radius", _REQUIRED), ("centre", (0, 0, 0))],
                "Packs a ball (basalt-pack sphere); center is another spelling of centre.")
mesh = _shape("mesh", [("file", _REQUIRED)],
              "Packs the inside of a closed triangle mesh, OFF, STL, OBJ or PLY (basalt-pack mesh FILE).")

__all__ = ["box", "cylinder", "sphere", "mesh"]
