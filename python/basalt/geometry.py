"""Sphere assemblies: basalt.Geometry, read_geometry, and writing them (HDF5 or ESyS-Particle's .geo).

Reading and writing go through the C++ I/O layer that basalt-pack and basalt-run use (basalt._core), so a
file is checked the same way and a bad one is refused with the same message, naming the file and the line
(.geo) or dataset (.h5): ``basalt.FormatError: bad.geo: line 10: radius must be finite and > 0, got -0.5``.
"""

import os

import numpy as np

from . import _core_loader


class Geometry:
    """Particles (sorted by id), bonds, box, units and provenance, as basalt-pack writes and basalt-run reads.

    particles   dict of numpy arrays, one row per particle: "id" (N,) int64, "position" (N, 3) float64,
                "radius" (N,) float64, "tag" (N,) int32, and "mass" (N,) float64 when the file has masses
    bonds       dict: "pairs" (M, 2) int64 (particle ids, smaller first), "tag" (M,) int32
    box_min, box_max   (3,) float64; periodic: tuple of 3 bools
    units       dict: length, time, force, mass ("" = derived from the other three)
    attrs       provenance strings (creator, command_line, source_file ...)
    statistics  dict of float64 arrays (the packer's: solid_fraction, radius_histogram_counts ...)
    pack_stats  what basalt.pack made (particles, solid_fraction, bonds, note ...); None for a file read
    source      the file it was read from, or None

    Build one from arrays with Geometry(position, radius, ...) (ids 0..N-1, tags 0 and the particles' extent
    as box unless given), change the arrays in place, and write it with write(path).
    """

    def __init__(self, position, radius, *, id=None, tag=None, mass=None, bonds=None, bond_tag=None,
                 box_min=None, box_max=None, periodic=(False, False, False), units=None, attrs=None,
                 statistics=None):
        position = np.array(position, dtype=np.float64).reshape(-1, 3)
        n = len(position)
        radius = np.array(radius, dtype=np.float64).reshape(n)
        self.particles = {
            "id": np.arange(n, dtype=np.int64) if id is None else np.array(id, dtype=np.int64).reshape(n),
            "position": position,
            "radius": radius,
            "tag": np.zeros(n, np.int32) if tag is None else np.array(tag, dtype=np.int32).reshape(n),
        }
        if mass is not None:
            self.particles["mass"] = np.array(mass, dtype=np.float64).reshape(n)
        pairs = np.zeros((0, 2), np.int64) if bonds is None else np.array(bonds, dtype=np.int64).reshape(-1, 2)
        self.bonds = {
            "pairs": pairs,
            "tag": np.zeros(len(pairs), np.int32) if bond_tag is None
            else np.array(bond_tag, dtype=np.int32).reshape(len(pairs)),
        }
        if box_min is None:
            box_min = (position - radius[:, None]).min(axis=0) if n else np.zeros(3)
        if box_max is None:
            box_max = (position + radius[:, None]).max(axis=0) if n else np.zeros(3)
        self.box_min = np.array(box_min, dtype=np.float64).reshape(3)
        self.box_max = np.array(box_max, dtype=np.float64).reshape(3)
        self.periodic = tuple(bool(p) for p in periodic)
        self.units = {"length": "mm", "time": "ms", "force": "N", "mass": ""}
        self.units.update(units or {})
        self.attrs = dict(attrs or {})
        self.statistics = {k: np.asarray(v, dtype=np.float64).reshape(-1) for k, v in (statistics or {}).items()}
        self.pack_stats = None
        self.source = None

    @classmethod
    def _from_core(cls, d, source=None):
        """From the dict basalt._core returns (arrays already of the schema's types)."""
        g = cls.__new__(cls)
        g.particles = {k: d[k] for k in ("id", "position", "radius", "tag")}
        if d["mass"] is not None:
            g.particles["mass"] = d["mass"]
        g.bonds = {"pairs": d["bonds"], "tag": d["bond_tag"]}
        g.box_min, g.box_max = d["box_min"], d["box_max"]
        g.periodic = tuple(d["periodic"])
        g.units = dict(d["units"])
        g.attrs = dict(d["attributes"])
        g.statistics = dict(d["statistics"])
        g.pack_stats = None
        g.source = None if source is None else os.fspath(source)
        return g

    @property
    def positions(self):
        """The particles' centres, (N, 3) float64 (particles["position"])."""
        return self.particles["position"]

    @property
    def n_particles(self):
        return len(self.particles["id"])

    @property
    def n_bonds(self):
        return len(self.bonds["pairs"])

    def __len__(self):
        return self.n_particles

    def __repr__(self):
        where = f" from {self.source}" if self.source else ""
        return (f"<basalt.Geometry: {self.n_particles} particles, {self.n_bonds} bonds, box "
                f"{tuple(float(v) for v in self.box_min)} .. {tuple(float(v) for v in self.box_max)}{where}>")

    def write(self, path):
        """Writes the geometry by extension: .h5/.hdf5 (Basalt's schema, docs/formats.md) or .geo
        (ESyS-Particle; masses, units, provenance and statistics are not stored there). Atomic (a temporary
        name, then renamed). The geometry is checked first, with basalt-pack's checks: a FormatError names the
        file and the first bad particle or bond. Returns the path."""
        p = self.particles
        mass = p.get("mass")
        _core_loader.core().write_geometry(
            os.fspath(path), id=_column(p["id"], np.int64, 'particles["id"]'),
            position=_column(p["position"], np.float64, 'particles["position"]'),
            radius=_column(p["radius"], np.float64, 'particles["radius"]'),
            tag=_column(p["tag"], np.int32, 'particles["tag"]'),
            mass=None if mass is None else _column(mass, np.float64, 'particles["mass"]'),
            bonds=_column(self.bonds["pairs"], np.int64, 'bonds["pairs"]'),
            bond_tag=_column(self.bonds["tag"], np.int32, 'bonds["tag"]'),
            box_min=_column(self.box_min, np.float64, "box_min"), box_max=_column(self.box_max, np.float64, "box_max"),
            periodic=tuple(bool(v) for v in self.periodic), units=self.units,
            attributes={str(k): str(v) for k, v in self.attrs.items()},
            statistics={k: _column(v, np.float64, f'statistics["{k}"]').reshape(-1) for k, v in self.statistics.items()})
        return path


def _column(values, dtype, name):
    """An array as the file stores it (C order, of `dtype`): numbers that fit, whole numbers for integer types;
    otherwise a ValueError naming it (a shape the schema does not have is the writer's error)."""
    a = np.asarray(values)
    if a.dtype == dtype:
        return np.ascontiguousarray(a)
    if np.issubdtype(dtype, np.integer) and a.size:
        if not (np.issubdtype(a.dtype, np.integer) or np.issubdtype(a.dtype, np.bool_)):
            if not np.issubdtype(a.dtype, np.number) or not np.all(np.isfinite(a)) or np.any(a != np.round(a)):
                raise ValueError(f"{name}: whole numbers expected, got {a.dtype} values such as {a.ravel()[0]!r}")
        info = np.iinfo(dtype)
        if a.min() < info.min or a.max() > info.max:
            raise ValueError(f"{name}: values from {a.min()} to {a.max()} do not fit {np.dtype(dtype).name}")
    try:
        return np.ascontiguousarray(a, dtype=dtype)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: not numbers ({e})") from e


def read_geometry(path):
    """Reads a geometry file by extension: .h5/.hdf5 (Basalt's schema: basalt-pack's output, basalt-run's
    input) or .geo (ESyS-Particle's LSMGeometry 1.1/1.2, as GenGeo writes it), with basalt-run's reader.
    Returns a Geometry (particles sorted by id). A bad file raises basalt.FormatError naming the file and the
    line or dataset; a checkpoint is refused with a hint to read_checkpoint."""
    d = _core_loader.core().read_geometry(os.fspath(path))
    return Geometry._from_core(d, source=path)
