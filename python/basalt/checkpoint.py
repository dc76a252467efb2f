"""basalt-run's checkpoints (schema basalt-checkpoint, docs/formats.md) as numpy arrays.

read_checkpoint(path) reads every group of one checkpoint file (or the latest complete one of a folder, as
``basalt-run --restart out/`` picks it); read_checkpoints(folder or glob) reads a series, sorted by step. The
file is first checked by basalt-run's own header check (schema, version, completion mark, every dataset's
type and shape, the walls and clock; basalt._core), so a file basalt-run would refuse is refused here with the
same message; then h5py reads the datasets, whichever the file holds, so a dataset added to the schema
appears without a change here.
"""

import glob
import os
import re

import numpy as np

from . import _core_loader
from ._errors import FormatError

_CKPT_NAME = re.compile(r"^ckpt_(\d+)\.h5$")


def _h5py():
    try:
        import h5py
    except ImportError as e:
        raise ImportError("basalt's checkpoint reader needs h5py (Debian: apt-get install python3-h5py; "
                          "/usr/bin/python3 sees it, a pyenv python3 may not)") from e
    return h5py


def _value(v):
    """An HDF5 attribute as Python: str, int, float, or a numpy array for vectors."""
    if isinstance(v, bytes):
        return v.decode("utf-8")
    if isinstance(v, np.ndarray):
        return v.item() if v.shape == () else v
    if isinstance(v, np.generic):
        return v.item()
    return v


def _datasets(group):
    """Every dataset directly under an h5py group, by name, as numpy arrays."""
    return {name: obj[()] for name, obj in group.items() if not hasattr(obj, "keys")}


class Checkpoint:
    """One checkpoint: the run's state at one step.

    step, time, dt   the clock (root attributes); scene_text: the scene file's text, verbatim
    attrs            every root attribute (provenance strings, units, box, decomposition ...) as Python values
    particles        dict: every dataset of /particles by name, one row per particle in id order: "id",
                     "position" (N, 3), "velocity" (N, 3), "radius", "mass", "tag", and whatever the run stored
                     ("inverse_mass", "position_at_rebuild", "force_x" ..., scene fields such as "bonds_broken")
    bonds            dict: every dataset of /bonds: "pairs" (M, 2) ids, "tag", "rest_length", "broken" (0 intact,
                     else broken; docs/formats.md), "break_position" (B, 3) when some bond broke
    contacts         dict: "ids" (C, 2), "model" (C,), "history" (C, width) and "width", when the run stored
                     contact histories; empty otherwise
    walls            dict name -> dict ("index", "position", "normal", "velocity", "force", "motion_state" if
                     stored), in the walls' order; empty when the scene has none
    statistics       dict of /statistics arrays (the packer's, carried over)
    groups           any other top-level group's datasets, by group name (none in schema version 1)
    units            dict: length, time, force, mass
    path             the file read
    """

    def __init__(self, path):
        self.path = os.fspath(path)
        self.attrs = {}
        self.particles = {}
        self.bonds = {}
        self.contacts = {}
        self.walls = {}
        self.statistics = {}
        self.groups = {}

    step = property(lambda self: self.attrs["step"], doc="the step number")
    time = property(lambda self: self.attrs["time"], doc="the simulated time [time unit]")
    dt = property(lambda self: self.attrs["dt"], doc="the time step [time unit]")
    scene_text = property(lambda self: self.attrs.get("scene_text", ""), doc="the scene file's text")

    @property
    def units(self):
        return {k: self.attrs.get(f"{k}_unit", "") for k in ("length", "time", "force", "mass")}

    @property
    def positions(self):
        """The particles' centres, (N, 3) float64 (particles["position"])."""
        return self.particles["position"]

    @property
    def velocities(self):
        """The particles' velocities, (N, 3) float64 (particles["velocity"])."""
        return self.particles["velocity"]

    @property
    def n_particles(self):
        return len(self.particles["id"])

    @property
    def n_bonds(self):
        return len(self.bonds["pairs"])

    def __len__(self):
        return self.n_particles

    def __repr__(self):
        return (f"<basalt.Checkpoint step {self.step}, time {self.time:g}: {self.n_particles} particles, "
                f"{self.n_bonds} bonds, {len(self.walls)} walls, {len(self.contacts.get('ids', ()))} contact "
                f"histories from {self.path}>")

    def to_geometry(self, bonds="intact"):
        """The particles and bonds as a basalt.Geometry (positions and masses of this step; ids, radii and tags),
        e.g. to write the settled state as a new run's geometry. bonds: "intact" (default: broken bonds left
        out), "all", or "none". Bond tags are the run's bond groups (docs/formats.md)."""
        from .geometry import Geometry

        pairs, tags = self.bonds["pairs"], self.bonds["tag"]
        if bonds == "intact":
            keep = self.bonds["broken"] == 0
            pairs, tags = pairs[keep], tags[keep]
        elif bonds == "none":
            pairs, tags = pairs[:0], tags[:0]
        elif bonds != "all":
            raise ValueError(f"bonds={bonds!r}: 'intact', 'all' or 'none'")
        a = self.attrs
        p = self.particles
        g = Geometry(p["position"], p["radius"], id=p["id"], tag=p["tag"], mass=p.get("mass"), bonds=pairs,
                     bond_tag=tags, box_min=a["box_min"], box_max=a["box_max"],
                     periodic=tuple(bool(v) for v in a["periodic"]), units=self.units,
                     statistics=self.statistics)
        g.attrs = {"source_file": self.path, "source_format": f"basalt-checkpoint, step {self.step}"}
        return g


def _check(path):
    """basalt-run's header check of a checkpoint (raises FormatError with its message)."""
    _core_loader.core().check_checkpoint(path)


def _read_file(path):
    path = os.fspath(path)
    _check(path)
    h5py = _h5py()
    c = Checkpoint(path)
    with h5py.File(path, "r") as f:
        c.attrs = {k: _value(v) for k, v in f.attrs.items()}
        for name, obj in f.items():
            if name == "particles":
                c.particles = _datasets(obj)
            elif name == "bonds":
                c.bonds = _datasets(obj)
            elif name == "statistics":
                c.statistics = _datasets(obj)
            elif name == "contacts":
                c.contacts = _datasets(obj)
                c.contacts["width"] = _value(obj.attrs["width"])
            elif name == "walls":
                walls = []
                for wname, w in obj.items():
                    d = {"index": _value(w.attrs["index"])}
                    d.update(_datasets(w))
                    walls.append((d["index"], wname, d))
                c.walls = {wname: d for _, wname, d in sorted(walls, key=lambda t: t[0])}
            elif hasattr(obj, "keys"):
                c.groups[name] = _datasets(obj)
    return c


def _step_of(path):
    m = _CKPT_NAME.match(os.path.basename(path))
    return int(m.group(1)) if m else None


def checkpoint_files(where):
    """The checkpoint files a folder (its ckpt_<step>.h5), a glob pattern or a list of paths names, sorted by
    step (the number in the name, else the file's order); .partial files are never included."""
    if isinstance(where, (list, tuple)):
        files = [os.fspath(p) for p in where]
    elif os.path.isdir(where):
        files = [os.path.join(where, n) for n in os.listdir(where) if _CKPT_NAME.match(n)]
    else:
        files = glob.glob(os.fspath(where))
        if not files and not glob.has_magic(os.fspath(where)):
            raise FileNotFoundError(f"{where}: no such file or folder")
    files = [f for f in files if not f.endswith(".partial")]
    return sorted(files, key=lambda f: (_step_of(f) is None, _step_of(f) or 0, f))


def read_checkpoint(path):
    """Reads one checkpoint: a ckpt_<step>.h5 file; a run's output folder, whose latest complete checkpoint is
    read (the one ``basalt-run --restart <folder>`` continues from); or a glob pattern, whose match with the
    highest step is read. Returns a Checkpoint. A file basalt-run would refuse (another schema, a newer version,
    not completely written, a damaged dataset) raises basalt.FormatError naming the file and the attribute or
    dataset."""
    _h5py()  # says what is missing before anything else
    path = os.fspath(path)
    if os.path.isdir(path):
        latest = _core_loader.core().latest_complete_checkpoint(path)
        if not latest:
            raise FormatError.at(path, "", "no complete checkpoint (ckpt_<step>.h5) in this folder")
        path = latest
    elif not os.path.exists(path):
        matches = checkpoint_files(path) if glob.has_magic(path) else []
        if not matches:
            raise FileNotFoundError(f"{path}: no such file or folder" if not glob.has_magic(path)
                                    else f"{path}: no file matches")
        path = matches[-1]
    return _read_file(path)


def iter_checkpoints(where):
    """read_checkpoints one at a time (a generator): for series larger than memory."""
    _h5py()
    for f in checkpoint_files(where):
        yield _read_file(f)


def read_checkpoints(where):
    """Reads a series: every ckpt_<step>.h5 of a folder, the files a glob pattern matches
    ("out/wave/ckpt_0002*.h5") or a list of paths, sorted by step. Returns a list of Checkpoint (all in
    memory: iter_checkpoints reads one at a time)."""
    return list(iter_checkpoints(where))
