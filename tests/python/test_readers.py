"""basalt.read_geometry, read_checkpoint(s) and read_fields against the files basalt-pack and basalt-run write,
h5py's direct reads, known counts, and bad input (the errors name the file and the line or dataset)."""

import csv
import math
import shutil

import h5py
import numpy as np
import pytest

import basalt

from conftest import CUBE, ROOT, run


# ---------------------------------------------------------------------------------------------- geometries

def test_cube1_geo_counts_and_values():
    g = basalt.read_geometry(CUBE)
    assert g.n_particles == 8948 and g.n_bonds == 30090 and len(g) == 8948  # tests/data/README.md
    p = g.particles
    assert p["id"].dtype == np.int64 and p["position"].shape == (8948, 3) and p["tag"].dtype == np.int32
    assert np.all(np.diff(p["id"]) > 0)  # sorted by id
    assert "mass" not in p  # .geo has no masses
    # the file's first particle line: 1.42068311 0.6730510364 1.273367548 0.4529056675 0 1
    assert p["id"][0] == 0 and p["tag"][0] == 1
    assert p["position"][0].tolist() == [1.42068311, 0.6730510364, 1.273367548]
    assert p["radius"][0] == 0.4529056675
    # third line: id 516; first bond line: 0 516 0; last: 175498 185704 0
    i = np.searchsorted(p["id"], 516)
    assert p["id"][i] == 516 and p["radius"][i] == 0.9729658375
    assert g.bonds["pairs"][0].tolist() == [0, 516] and g.bonds["pairs"][-1].tolist() == [175498, 185704]
    assert np.all(g.bonds["pairs"][:, 0] < g.bonds["pairs"][:, 1]) and not g.bonds["tag"].any()
    assert g.box_min.tolist() == [0, 0, 0] and g.box_max.tolist() == [15, 15, 15]
    assert g.periodic == (False, False, False)
    assert g.attrs["source_format"] == "LSMGeometry 1.2" and g.positions is p["position"]


def test_geometry_round_trip(tmp_path):
    g = basalt.read_geometry(CUBE)
    g.write(tmp_path / "cube.h5")
    h = basalt.read_geometry(tmp_path / "cube.h5")
    for k in g.particles:
        assert np.array_equal(g.particles[k], h.particles[k]), k
    assert np.array_equal(g.bonds["pairs"], h.bonds["pairs"]) and np.array_equal(g.bonds["tag"], h.bonds["tag"])
    with h5py.File(tmp_path / "cube.h5", "r") as f:  # what h5py sees in the written file
        assert f.attrs["schema"] == "basalt-geometry"
        assert np.array_equal(f["particles/position"][()], g.positions)
        assert f["bonds/pairs"].shape == (30090, 2)
    # written as .geo again, the particle lines are GenGeo's, character for character (docs/formats.md), in id
    # order
    h.write(tmp_path / "again.geo")
    lines = open(tmp_path / "again.geo").read().split("\n")[7:8955]
    assert lines == sorted(open(CUBE).read().split("\n")[7:8955], key=lambda line: int(line.split()[4]))


def test_geometry_from_arrays(tmp_path):
    g = basalt.Geometry([[0, 0, 0], [2, 0, 0], [1, 1.7, 0]], [1, 1, 1], bonds=[[0, 1], [2, 1]], tag=[1, 2, 3],
                        mass=[4, 4, 4], attrs={"made_by": "test"})
    assert g.box_min.tolist() == [-1, -1, -1] and g.box_max.tolist() == [3, 2.7, 1]
    g.write(tmp_path / "three.h5")
    h = basalt.read_geometry(tmp_path / "three.h5")
    assert h.bonds["pairs"].tolist() == [[0, 1], [1, 2]]  # stored smaller id first
    assert h.particles["mass"].tolist() == [4, 4, 4] and h.attrs["made_by"] == "test"
    assert h.particles["tag"].tolist() == [1, 2, 3] and h.units["length"] == "mm"


def test_geometry_write_errors(tmp_path):
    g = basalt.Geometry([[0, 0, 0], [2, 0, 0]], [1, -0.5])
    with pytest.raises(basalt.FormatError) as e:
        g.write(tmp_path / "bad.geo")
    assert str(e.value).startswith(f"{tmp_path / 'bad.geo'}: ") and "radius" in str(e.value)
    assert not (tmp_path / "bad.geo").exists()
    g = basalt.Geometry([[0, 0, 0], [2, 0, 0]], [1, 1], bonds=[[0, 7]])
    with pytest.raises(basalt.FormatError, match="7"):
        g.write(tmp_path / "bad.h5")
    with pytest.raises(basalt.FormatError, match=r"\.txt"):
        g.write(tmp_path / "x.txt")
    with pytest.raises(basalt.FormatError, match="folder '.*nowhere' does not exist"):
        basalt.read_geometry(CUBE).write(tmp_path / "nowhere" / "x.h5")
    # arrays changed by hand: numpy's default integers are fine, values that do not fit are named
    g = basalt.Geometry([[0, 0, 0], [2, 0, 0]], [1, 1])
    g.particles["tag"] = np.array([1, 2])
    g.write(tmp_path / "ok.h5")
    assert basalt.read_geometry(tmp_path / "ok.h5").particles["tag"].tolist() == [1, 2]
    g.particles["tag"] = np.array([1, 2 ** 40])
    with pytest.raises(ValueError, match=r'particles\["tag"\]: values from 1 to 1099511627776 do not fit int32'):
        g.write(tmp_path / "x.h5")
    g.particles["tag"] = [1.5, 2]
    with pytest.raises(ValueError, match=r'particles\["tag"\]: whole numbers expected'):
        g.write(tmp_path / "x.h5")
    g.particles["tag"] = [1, 2]
    g.particles["position"] = g.positions[:, :2]
    with pytest.raises(ValueError, match=r'particles\["position"\]: shape \(2, 2\), expected \(2, 3\)'):
        g.write(tmp_path / "x.h5")
    assert not (tmp_path / "x.h5").exists()


def geo_text(particles, bonds=()):
    lines = ["LSMGeometry 1.2", "BoundingBox 0 0 0 10 10 10", "PeriodicBoundaries 0 0 0", "Dimension 3D",
             "BeginParticles", "Simple", str(len(particles))] + particles + ["EndParticles"]
    if bonds:
        lines += ["BeginConnect", str(len(bonds))] + list(bonds) + ["EndConnect"]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("particles, bonds, where, what", [
    (["1 1 1 0.5 0 0", "2 2 2 0.5 1 0", "3 3 3 -0.5 2 0"], (), "line 10", "radius must be finite and > 0, got -0.5"),
    (["1 1 1 0.5 0 0", "2 2 2 0.5 0 0"], (), "line 9", "duplicate particle id 0 (first on line 8)"),
    (["1 1 1 0.5 0 0", "2 2 2 0.5 1 0"], ("0 5 0",), "line 13", "bond refers to particle id 5, which does not exist"),
    (["1 1 x 0.5 0 0"], (), "line 8", ""),
])
def test_bad_geo_names_file_and_line(tmp_path, particles, bonds, where, what):
    bad = tmp_path / "bad.geo"
    bad.write_text(geo_text(particles, bonds))
    with pytest.raises(basalt.FormatError) as e:
        basalt.read_geometry(bad)
    assert str(e.value).startswith(f"{bad}: {where}: "), str(e.value)
    assert what in str(e.value)
    assert e.value.file == str(bad) and e.value.where == where and isinstance(e.value, ValueError)


def test_bad_h5_names_dataset(tmp_path):
    bad = tmp_path / "bad.h5"
    basalt.Geometry(np.arange(30.0).reshape(10, 3), np.ones(10)).write(bad)
    with h5py.File(bad, "r+") as f:
        del f["particles/radius"]
        f["particles/radius"] = np.ones(9)
    with pytest.raises(basalt.FormatError) as e:
        basalt.read_geometry(bad)
    assert str(e.value) == f"{bad}: /particles/radius: 9 values for 10 particles"
    with pytest.raises(basalt.FormatError, match="no such file|cannot open|does not exist"):
        basalt.read_geometry(tmp_path / "missing.h5")


# ---------------------------------------------------------------------------------------------- a short run

@pytest.fixture(scope="module")
def runs(bin_dir, tmp_path_factory):
    """Two short basalt-run runs: the wave on a bonded 5 mm cube (walls, bonds, fields every step) and Hertz-Mindlin
    grains settling in a cylinder (contact histories)."""
    d = tmp_path_factory.mktemp("runs")
    cube = basalt.pack.box(size=(5, 5, 5), rmin=0.3, rmax=1.0, seed=7, output=d / "cube.h5")
    basalt.pack.cylinder(radius=4, height=3, rmin=0.45, rmax=0.55, no_bonds=True, seed=5, output=d / "cyl.h5")
    run([bin_dir / "basalt-run", ROOT / "scenes" / "wave.toml", "--geometry", d / "cube.h5", "--steps", 60,
         "--checkpoint-every", 20, "--fields-every", 1, "--output", d / "wave"])
    run([bin_dir / "basalt-run", ROOT / "tests" / "solver" / "hertz_restart.toml", "--geometry", d / "cyl.h5",
         "--steps", 200, "--checkpoint-every", 100, "--output", d / "hertz"])
    return {"dir": d, "cube": cube}


def h5_datasets(path, group):
    with h5py.File(path, "r") as f:
        return {k: v[()] for k, v in f[group].items() if isinstance(v, h5py.Dataset)}


def test_checkpoint_against_h5py(runs):
    wave = runs["dir"] / "wave"
    c = basalt.read_checkpoint(wave / "ckpt_000040.h5")
    cube = runs["cube"]
    assert c.step == 40 and math.isclose(c.time, 40 * c.dt) and c.dt == 1e-3  # scenes/wave.toml's dt
    assert c.n_particles == cube.n_particles and c.n_bonds == cube.n_bonds
    assert np.array_equal(c.particles["id"], cube.particles["id"])
    assert np.array_equal(c.particles["radius"], cube.particles["radius"])
    for group, got in (("particles", c.particles), ("bonds", c.bonds), ("statistics", c.statistics)):
        want = h5_datasets(wave / "ckpt_000040.h5", group)
        assert sorted(got) == sorted(want), group
        for k in want:
            assert got[k].dtype == want[k].dtype and got[k].tobytes() == want[k].tobytes(), (group, k)
    assert {"velocity", "mass", "inverse_mass", "position_at_rebuild"} <= set(c.particles)
    assert c.positions.shape == (c.n_particles, 3) and c.velocities is c.particles["velocity"]
    assert not c.bonds["broken"].any() and c.bonds["rest_length"].shape == (c.n_bonds,)
    # the wave's one wall, moving up as a half-sine
    assert list(c.walls) == ["base"] and c.walls["base"]["index"] == 0
    assert c.walls["base"]["normal"].tolist() == [0, 0, 1] and c.walls["base"]["velocity"][2] > 0
    with h5py.File(wave / "ckpt_000040.h5", "r") as f:
        assert c.walls["base"]["force"].tobytes() == f["walls/base/force"][()].tobytes()
        assert c.attrs.keys() == f.attrs.keys() and c.scene_text == f.attrs["scene_text"]
        assert c.attrs["box_min"].tolist() == f.attrs["box_min"].tolist()
    assert c.contacts == {} and c.units["length"] == "mm" and "[[walls]]" in c.scene_text
    assert "step 40" in repr(c)


def test_checkpoint_contacts(runs):
    path = runs["dir"] / "hertz" / "ckpt_000200.h5"
    c = basalt.read_checkpoint(path)
    want = h5_datasets(path, "contacts")
    assert sorted(c.contacts) == sorted(list(want) + ["width"])
    with h5py.File(path, "r") as f:
        assert c.contacts["width"] == f["contacts"].attrs["width"] == 3
    n = len(want["ids"])
    assert n > 0 and c.contacts["history"].shape == (n, 3) and c.contacts["ids"].shape == (n, 2)
    for k in want:
        assert c.contacts[k].tobytes() == want[k].tobytes()
    # first a particle id; second a particle id, or a wall as -1 - its index (grains on the floor)
    first, second = c.contacts["ids"].T
    assert set(first) <= set(c.particles["id"]) and set(second[second >= 0]) <= set(c.particles["id"])
    assert set(second[second < 0]) == {-1}
    assert "angular_velocity_x" in c.particles and c.n_bonds == 0 and list(c.walls) == ["floor"]


def test_checkpoint_series_folder_and_glob(runs):
    wave = runs["dir"] / "wave"
    series = basalt.read_checkpoints(wave)
    assert [c.step for c in series] == [20, 40, 60]
    assert [c.step for c in basalt.read_checkpoints(str(wave / "ckpt_00004*.h5"))] == [40]
    assert [c.step for c in basalt.read_checkpoints([wave / "ckpt_000060.h5", wave / "ckpt_000020.h5"])] == [20, 60]
    assert basalt.read_checkpoint(wave).step == 60  # a folder: its latest complete checkpoint
    assert basalt.read_checkpoint(str(wave / "ckpt_0000[24]*.h5")).step == 40  # a glob: its highest step
    with pytest.raises(FileNotFoundError, match="no file matches"):
        basalt.read_checkpoint(str(wave / "ckpt_9*.h5"))
    # positions move between checkpoints, ids do not
    assert not np.array_equal(series[0].positions, series[2].positions)
    assert np.array_equal(series[0].particles["id"], series[2].particles["id"])


def test_checkpoint_to_geometry(runs, tmp_path):
    c = basalt.read_checkpoint(runs["dir"] / "wave" / "ckpt_000060.h5")
    g = c.to_geometry()
    g.write(tmp_path / "state.h5")
    h = basalt.read_geometry(tmp_path / "state.h5")
    assert np.array_equal(h.positions, c.positions) and np.array_equal(h.particles["mass"], c.particles["mass"])
    assert h.n_bonds == c.n_bonds and h.attrs["source_format"] == "basalt-checkpoint, step 60"


def test_bad_checkpoints_are_refused_with_basalt_runs_message(runs, tmp_path):
    src = runs["dir"] / "wave" / "ckpt_000020.h5"
    cut = tmp_path / "ckpt_000020.h5"
    shutil.copy(src, cut)
    with h5py.File(cut, "r+") as f:
        del f.attrs["complete"]
    with pytest.raises(basalt.FormatError) as e:
        basalt.read_checkpoint(cut)
    assert str(e.value) == (f"{cut}: attribute 'complete' of /: missing: the checkpoint was not completely "
                            "written (did the run stop while writing it?)")
    assert e.value.where == "attribute 'complete' of /"
    # the folder holds only that one: no complete checkpoint
    with pytest.raises(basalt.FormatError, match="no complete checkpoint"):
        basalt.read_checkpoint(tmp_path)
    with pytest.raises(basalt.FormatError, match=r"is 'basalt-geometry', expected 'basalt-checkpoint' \(this is a "
                                                 r"geometry file, not a checkpoint\)"):
        basalt.read_checkpoint(runs["dir"] / "cube.h5")
    with pytest.raises(basalt.FormatError, match="this is a checkpoint: read it with read_checkpoint"):
        basalt.read_geometry(src)
    with pytest.raises(FileNotFoundError):
        basalt.read_checkpoint(tmp_path / "ckpt_000001.h5")
    short = tmp_path / "short" / "ckpt_000020.h5"
    short.parent.mkdir()
    short.write_bytes(src.read_bytes()[:4096])
    with pytest.raises(basalt.FormatError, match=str(short)):
        basalt.read_checkpoint(short)


# ---------------------------------------------------------------------------------------------- field series

def test_fields_against_csv(runs):
    wave = runs["dir"] / "wave"
    f = basalt.read_fields(wave)  # the folder: its fields.csv
    with open(wave / "fields.csv") as fh:
        rows = list(csv.reader(fh))
    assert f.dtype.names == tuple(rows[0]) and rows[0][:3] == ["step", "time", "kinetic_energy"]
    assert len(f) == 60 and f["step"].tolist() == list(range(1, 61)) and f["step"].dtype == np.int64
    for k, name in enumerate(rows[0][1:], start=1):
        assert f[name].tolist() == [float(r[k]) for r in rows[1:]]
    assert np.array_equal(f.time, f["time"]) and f.kinetic_energy[-1] > 0


def test_fields_empty_cells_and_pandas(tmp_path):
    p = tmp_path / "fields.csv"
    p.write_text("step,time,a,b\n1,0.5,1,\n\n2,1,nan,-inf\r\n3,1.5,,4\n")
    f = basalt.read_fields(p)
    assert f["step"].tolist() == [1, 2, 3] and f["time"].tolist() == [0.5, 1, 1.5]
    assert math.isnan(f["b"][0]) and math.isnan(f["a"][1]) and f["b"][1] == -math.inf and f["b"][2] == 4
    p.write_text("step,time,a\n")
    assert len(basalt.read_fields(p)) == 0
    try:
        import pandas  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError, match="python3-pandas"):
            basalt.read_fields(p, as_pandas=True)
    else:
        assert list(basalt.read_fields(p, as_pandas=True).columns) == ["step", "time", "a"]


@pytest.mark.parametrize("text, where, what", [
    ("step,time,kinetic_energy\n1,0.1,2\n\n3,0.3\n", "line 4", "2 values, expected 3 (step,time,kinetic_energy)"),
    ("step,time,kinetic_energy\n1,0.1,2\n2,0.2,1.2.3\n", "line 3", 'column "kinetic_energy": "1.2.3" is not a number'),
    ("step,time,e\n1.5,0.1,2\n", "line 2", 'column "step": "1.5" is not a number'),
    ("step,time,e\n1,nan,2\n", "line 2", 'column "time": "nan" is not a number'),
    ("time,step,e\n", "line 1", 'header must be "step,time,<field>...", found "time,step,e"'),
    ("step,time,e,e\n", "line 1", 'column "e" named twice in header'),
    ("", "line 1", 'empty file: expected a header "step,time,..."'),
])
def test_bad_fields_name_file_and_line(tmp_path, text, where, what):
    p = tmp_path / "fields.csv"
    p.write_text(text)
    with pytest.raises(basalt.FormatError) as e:
        basalt.read_fields(p)
    assert str(e.value) == f"{p}: {where}: {what}" and e.value.where == where


def test_missing_fields_file(tmp_path):
    with pytest.raises(basalt.FormatError, match="no such file"):
        basalt.read_fields(tmp_path)
