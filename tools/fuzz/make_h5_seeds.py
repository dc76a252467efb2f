#!/usr/bin/python3
"""Seed corpus of the HDF5 fuzz targets (fuzz_h5geo, fuzz_checkpoint; tools/fuzz/run.sh).

HDF5 is not instrumented, so libFuzzer's coverage comes from Basalt's readers only: byte mutations of a
valid file mostly stop in HDF5's header parser. Besides real files (written by basalt-pack and basalt-run),
this writes structural mutants of them with h5py, one damage each, so that every check of the readers is
reached from the start: wrong dataset lengths, types, ranks, missing groups and attributes, objects of
the wrong kind, huge declared dimensions with no data behind them (chunked and contiguous), unavailable
filters, out-of-range and non-finite values, inconsistent bonds, walls and contacts.

Usage (h5py: Debian's python3-h5py, hence /usr/bin/python3):
  /usr/bin/python3 tools/fuzz/make_h5_seeds.py bases BIN_DIR
      rewrites the real files committed in tools/fuzz/corpus/{h5geo,checkpoint}/ with BIN_DIR/basalt-pack
      and BIN_DIR/basalt-run (a build's bin/);
  /usr/bin/python3 tools/fuzz/make_h5_seeds.py mutants OUT_DIR
      writes the structural mutants of those files into OUT_DIR/{h5geo,checkpoint}/ (run.sh does this in
      its build folder: 183 files of 17-40 KB, too many to commit).
"""
import os
import shutil
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

GRANULAR = """
[geometry]
file = "lattice.h5"
[material]
density = 1.0
[particles]
rotation = true
[run]
dt = 1.0e-3
steps = 300
skin = 0.1
integrator = "symplectic_euler"
[[interactions]]
name = "friction"
type = "rot_friction"
K = 1000.0
Ks = 1000.0
mu = 0.6
[[walls]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
K = 1000.0
[[walls]]
name = "top"
point = [0.0, 0.0, 3.0]
normal = [0.0, 0.0, -1.0]
K = 1000.0
motion = {type = "servo", target_stress = 10.0, area = 4.0, gain = 1e-3, max_speed = 0.05}
[[body_forces]]
type = "gravity"
acceleration = [0.0, 0.0, -10.0]
[output]
directory = "out-granular"
compression = "fast"
"""

BONDED = """
[geometry]
file = "small.h5"
[material]
density = 1.0
[run]
dt = 1.0e-3
steps = 20
skin = 0.1
[[interactions]]
name = "bonds"
type = "linear_bond"
K = 1000.0
rest_length = "initial_distance"
break_strain = 0.001
[[interactions]]
name = "contacts"
type = "linear_elastic"
K = 1000.0
[[walls]]
name = "base"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
K = 1000.0
motion = { type = "half_sine", amplitude = 0.1, period = 0.01 }
[output]
directory = "out-bonded"
fields = [{type = "kinetic_energy"}, {type = "broken_bonds"}]
"""


def run(cmd, cwd):
    subprocess.run(cmd, cwd=cwd, check=True, stdout=subprocess.DEVNULL)


def replace(f, path, data, **kw):
    if path in f:
        del f[path]
    f.create_dataset(path, data=data, **kw)


def huge(f, path, shape, dtype, chunked):
    """A dataset declaring `shape` values with nothing written: HDF5 answers reads with fill values."""
    if path in f:
        del f[path]
    f.create_dataset(path, shape=shape, dtype=dtype, chunks=(min(1024, shape[0]),) + shape[1:] if chunked else None)


def set_attr(f, obj, name, value):
    target = f[obj]
    if name in target.attrs:
        del target.attrs[name]
    if value is not None:
        target.attrs[name] = value


def with_value(f, path, row, value):
    data = f[path][()]
    data[row] = value
    replace(f, path, data)


# Damage shared by both schemas (the checkpoint extends the geometry layout).
GEOMETRY_MUTANTS = {
    "radius_short": lambda f: replace(f, "particles/radius", f["particles/radius"][:-1]),
    "position_long": lambda f: replace(f, "particles/position", np.vstack([f["particles/position"][()]] * 2)),
    "tag_long": lambda f: replace(f, "particles/tag", np.append(f["particles/tag"][()], 7).astype("<i4")),
    "bond_tag_short": lambda f: replace(f, "bonds/tag", f["bonds/tag"][:-1]),
    "radius_int": lambda f: replace(f, "particles/radius", np.ones(len(f["particles/id"]), "<i4")),
    "id_float": lambda f: replace(f, "particles/id", f["particles/id"][()].astype("<f8")),
    "id_uint64_overflow": lambda f: replace(
        f, "particles/id", np.array([2**63 + k for k in range(len(f["particles/id"]))], "<u8")),
    "tag_int64_overflow": lambda f: replace(
        f, "particles/tag", np.full(len(f["particles/id"]), 2**40, "<i8")),
    "tag_string": lambda f: replace(f, "particles/tag", np.array([b"a"] * len(f["particles/id"]))),
    "position_rank1": lambda f: replace(f, "particles/position", f["particles/position"][()].ravel()),
    "position_4cols": lambda f: replace(
        f, "particles/position", np.hstack([f["particles/position"][()], np.zeros((len(f["particles/id"]), 1))])),
    "radius_rank2": lambda f: replace(f, "particles/radius", f["particles/radius"][()].reshape(-1, 1)),
    "id_scalar": lambda f: replace(f, "particles/id", np.int64(3)),
    "pairs_3cols": lambda f: replace(
        f, "bonds/pairs", np.hstack([f["bonds/pairs"][()], f["bonds/pairs"][()][:, :1]])),
    "no_particles": lambda f: f.__delitem__("particles"),
    "no_bonds": lambda f: f.__delitem__("bonds"),
    "no_id": lambda f: f.__delitem__("particles/id"),
    "radius_group": lambda f: (f.__delitem__("particles/radius"), f.create_group("particles/radius")),
    "bonds_dataset": lambda f: (f.__delitem__("bonds"), f.create_dataset("bonds", data=np.zeros(3))),
    "statistics_group": lambda f: f.create_group("statistics/nested"),
    "statistics_string": lambda f: replace(f, "statistics/words", np.array([b"x", b"y"])),
    "no_schema": lambda f: set_attr(f, "/", "schema", None),
    "schema_number": lambda f: set_attr(f, "/", "schema", np.int32(1)),
    "schema_version_2": lambda f: set_attr(f, "/", "schema_version", np.int32(2)),
    "schema_version_0": lambda f: set_attr(f, "/", "schema_version", np.int32(0)),
    "schema_version_float": lambda f: set_attr(f, "/", "schema_version", 1.5),
    "no_box_min": lambda f: set_attr(f, "/", "box_min", None),
    "box_inverted": lambda f: set_attr(f, "/", "box_min", np.array([5.0, 0, 0])),
    "box_nan": lambda f: set_attr(f, "/", "box_max", np.array([np.nan, 1, 1])),
    "box_two_values": lambda f: set_attr(f, "/", "box_max", np.array([1.0, 1.0])),
    "periodic_2": lambda f: set_attr(f, "/", "periodic", np.array([0, 2, 0], "u1")),
    "length_unit_number": lambda f: set_attr(f, "/", "length_unit", 3.0),
    "length_unit_array": lambda f: set_attr(f, "/", "length_unit", np.array([b"mm", b"m"])),
    "provenance_number": lambda f: set_attr(f, "/", "creator", np.int64(7)),
    "huge_id_chunked": lambda f: huge(f, "particles/id", (2**40,), "<i8", True),
    "huge_id_contiguous": lambda f: huge(f, "particles/id", (2**40,), "<i8", False),
    "huge_position_chunked": lambda f: huge(f, "particles/position", (2**33, 3), "<f8", True),
    "huge_pairs_chunked": lambda f: huge(f, "bonds/pairs", (2**34, 2), "<i8", True),
    "huge_statistics": lambda f: huge(f, "statistics/big", (2**36,), "<f8", True),
    "id_all_chunked_unwritten": lambda f: huge(f, "particles/id", (len(f["particles/id"]),), "<i8", True),
    "radius_deflate": lambda f: replace(f, "particles/radius", f["particles/radius"][()], chunks=(4,),
                                        compression="gzip", shuffle=True),
    "radius_lzf": lambda f: replace(f, "particles/radius", f["particles/radius"][()], chunks=(4,),
                                    compression="lzf"),
    "radius_nan": lambda f: with_value(f, "particles/radius", 1, np.nan),
    "radius_negative": lambda f: with_value(f, "particles/radius", 0, -1.0),
    "position_inf": lambda f: with_value(f, "particles/position", 2, [np.inf, 0, 0]),
    "mass_zero": lambda f: with_value(f, "particles/mass", 1, 0.0) if "particles/mass" in f else
    replace(f, "particles/mass", np.zeros(len(f["particles/id"]))),
    "ids_unsorted": lambda f: replace(f, "particles/id", f["particles/id"][()][::-1]),
    "ids_duplicate": lambda f: with_value(f, "particles/id", 1, f["particles/id"][0]),
    "bond_self": lambda f: with_value(f, "bonds/pairs", 0, [f["bonds/pairs"][0][0]] * 2),
    "bond_reversed": lambda f: with_value(f, "bonds/pairs", 0, f["bonds/pairs"][0][::-1]),
    "bond_missing_id": lambda f: with_value(f, "bonds/pairs", 0, [f["bonds/pairs"][0][0], 10**12]),
    "bond_duplicate": lambda f: with_value(f, "bonds/pairs", 1, f["bonds/pairs"][0]),
}

CHECKPOINT_MUTANTS = {
    "no_complete": lambda f: set_attr(f, "/", "complete", None),
    "complete_0": lambda f: set_attr(f, "/", "complete", np.uint8(0)),
    "complete_string": lambda f: set_attr(f, "/", "complete", "yes"),
    "no_mass": lambda f: f.__delitem__("particles/mass"),
    "velocity_short": lambda f: replace(f, "particles/velocity", f["particles/velocity"][:-1]),
    "velocity_nan": lambda f: with_value(f, "particles/velocity", 0, [np.nan, 0, 0]),
    "inverse_mass_nan": lambda f: with_value(f, "particles/inverse_mass", 0, np.nan),
    "inverse_mass_negative": lambda f: with_value(f, "particles/inverse_mass", 0, -2.0),
    "inverse_mass_short": lambda f: replace(f, "particles/inverse_mass", f["particles/inverse_mass"][:-1]),
    "rebuild_no_step": lambda f: set_attr(f, "/", "rebuild_step", None),
    "rebuild_step_future": lambda f: set_attr(f, "/", "rebuild_step", np.int64(10**9)),
    "rebuild_at_short": lambda f: replace(f, "particles/position_at_rebuild", f["particles/position_at_rebuild"][:-1]),
    "field_short": lambda f: replace(f, "particles/extra_field", np.zeros(2)),
    "field_nan": lambda f: replace(f, "particles/extra_field", np.full(len(f["particles/id"]), np.nan)),
    "field_int": lambda f: replace(f, "particles/extra_field", np.zeros(len(f["particles/id"]), "<i4")),
    "rest_length_negative": lambda f: with_value(f, "bonds/rest_length", 0, -1.0) if len(f["bonds/tag"]) else
    replace(f, "bonds/rest_length", np.array([-1.0])),
    "broken_3": lambda f: with_value(f, "bonds/broken", 0, 3) if len(f["bonds/tag"]) else
    replace(f, "bonds/broken", np.array([3], "u1")),
    "broken_int64_overflow": lambda f: replace(f, "bonds/broken", np.full(len(f["bonds/tag"]), 300, "<i8")),
    "no_walls": lambda f: f.__delitem__("walls"),
    "wall_index_duplicate": lambda f: [set_attr(f, "walls/" + w, "index", np.int64(0)) for w in f["walls"]],
    "wall_index_out_of_range": lambda f: set_attr(f, "walls/" + list(f["walls"])[0], "index", np.int64(99)),
    "wall_no_index": lambda f: set_attr(f, "walls/" + list(f["walls"])[0], "index", None),
    "wall_normal_zero": lambda f: replace(f, "walls/" + list(f["walls"])[0] + "/normal", np.zeros(3)),
    "wall_normal_4": lambda f: replace(f, "walls/" + list(f["walls"])[0] + "/normal", np.ones(4)),
    "wall_force_inf": lambda f: replace(f, "walls/" + list(f["walls"])[0] + "/force", np.array([np.inf, 0, 0])),
    "wall_dataset": lambda f: f.create_dataset("walls/not_a_group", data=np.zeros(3)),
    "wall_motion_state_nan": lambda f: replace(f, "walls/" + list(f["walls"])[-1] + "/motion_state",
                                               np.array([np.nan, 0, 0])),
    "step_negative": lambda f: set_attr(f, "/", "step", np.int64(-5)),
    "step_string": lambda f: set_attr(f, "/", "step", "100"),
    "dt_nan": lambda f: set_attr(f, "/", "dt", np.nan),
    "time_inf": lambda f: set_attr(f, "/", "time", np.inf),
    "scene_text_number": lambda f: set_attr(f, "/", "scene_text", 1.0),
    "huge_velocity_chunked": lambda f: huge(f, "particles/velocity", (2**33, 3), "<f8", True),
    "huge_field_chunked": lambda f: huge(f, "particles/extra_field", (2**36,), "<f8", True),
    "schema_geometry": lambda f: set_attr(f, "/", "schema", "basalt-geometry"),
}

CONTACT_MUTANTS = {
    "contacts_width_0": lambda f: set_attr(f, "contacts", "width", np.int64(0)),
    "contacts_width_65": lambda f: set_attr(f, "contacts", "width", np.int64(65)),
    "contacts_history_cols": lambda f: replace(f, "contacts/history", f["contacts/history"][:, :-1]),
    "contacts_model_short": lambda f: replace(f, "contacts/model", f["contacts/model"][:-1]),
    "contacts_model_negative": lambda f: with_value(f, "contacts/model", 0, -1),
    "contacts_missing_particle": lambda f: with_value(f, "contacts/ids", 0, [10**12, f["contacts/ids"][0][1]]),
    "contacts_missing_wall": lambda f: with_value(f, "contacts/ids", 0, [f["contacts/ids"][0][0], -100]),
    "contacts_history_nan": lambda f: with_value(f, "contacts/history", 0, np.nan),
    "huge_contacts_chunked": lambda f: huge(f, "contacts/ids", (2**34, 2), "<i8", True),
}


def mutate(base, out_dir, prefix, mutants):
    for name, damage in mutants.items():
        target = os.path.join(out_dir, f"{prefix}-{name}.h5")
        shutil.copyfile(base, target)
        with h5py.File(target, "r+") as f:
            damage(f)
        if os.path.getsize(target) > 100_000:
            sys.exit(f"{target}: {os.path.getsize(target)} bytes, over the 100 KB a seed may take")


def make_bases(bin_dir, corpus):
    """The real files: three geometries from basalt-pack, two checkpoints from basalt-run."""
    geo_dir, ckpt_dir = os.path.join(corpus, "h5geo"), os.path.join(corpus, "checkpoint")
    for d in (geo_dir, ckpt_dir):
        os.makedirs(d, exist_ok=True)
    pack, basalt_run = os.path.join(bin_dir, "basalt-pack"), os.path.join(bin_dir, "basalt-run")
    with tempfile.TemporaryDirectory() as tmp:
        run([pack, "box", "--size", "2,2,2", "--rmin", "0.25", "--rmax", "0.5", "-o", "small.h5", "-q"], tmp)
        run([pack, "box", "--size", "2,2,3", "--rmin", "0.2", "--rmax", "0.3", "--lattice", "--no-bonds",
             "-o", "lattice.h5", "-q"], tmp)
        run([pack, "cylinder", "--radius", "1", "--height", "1.5", "--rmin", "0.2", "--rmax", "0.4",
             "--tag-layer", "bottom:0.3:2", "-o", "cylinder.h5", "-q"], tmp)
        for scene, text in (("granular.toml", GRANULAR), ("bonded.toml", BONDED)):
            with open(os.path.join(tmp, scene), "w") as f:
                f.write(text)
        run([basalt_run, "granular.toml", "--checkpoint-every", "300", "--quiet"], tmp)
        run([basalt_run, "bonded.toml", "--checkpoint-every", "20", "--quiet"], tmp)
        for name in ("small.h5", "lattice.h5", "cylinder.h5"):
            shutil.copyfile(os.path.join(tmp, name), os.path.join(geo_dir, name))
        shutil.copyfile(os.path.join(tmp, "out-granular", "ckpt_000300.h5"), os.path.join(ckpt_dir, "granular.h5"))
        shutil.copyfile(os.path.join(tmp, "out-bonded", "ckpt_000020.h5"), os.path.join(ckpt_dir, "bonded.h5"))


def make_mutants(corpus, out):
    """The structural mutants of the committed real files, into OUT/h5geo and OUT/checkpoint."""
    geo_dir, ckpt_dir = os.path.join(out, "h5geo"), os.path.join(out, "checkpoint")
    for d in (geo_dir, ckpt_dir):
        os.makedirs(d, exist_ok=True)
    mutate(os.path.join(corpus, "h5geo", "small.h5"), geo_dir, "small", GEOMETRY_MUTANTS)
    mutate(os.path.join(corpus, "checkpoint", "bonded.h5"), ckpt_dir, "bonded",
           {**GEOMETRY_MUTANTS, **CHECKPOINT_MUTANTS})
    mutate(os.path.join(corpus, "checkpoint", "granular.h5"), ckpt_dir, "granular",
           {**CHECKPOINT_MUTANTS, **CONTACT_MUTANTS})


def main():
    corpus = os.path.join(HERE, "corpus")
    if len(sys.argv) == 3 and sys.argv[1] == "bases":
        make_bases(os.path.abspath(sys.argv[2]), corpus)
    elif len(sys.argv) == 3 and sys.argv[1] == "mutants":
        make_mutants(corpus, os.path.abspath(sys.argv[2]))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
