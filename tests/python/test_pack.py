"""basalt.pack against basalt-pack: the same options give the same spheres, bonds and statistics bit for bit,
and the same impossible options the same message."""

import inspect
import warnings

import h5py
import numpy as np
import pytest

import basalt
from basalt import _core

from conftest import run

# Attributes that say who wrote the file, and so differ between the command line and Python.
PROVENANCE = {"creator", "command_line"}


def h5_contents(path):
    """Every dataset and root attribute of an HDF5 file (provenance left out), by name."""
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
        for k, v in f.attrs.items():
            if k not in PROVENANCE:
                out["@" + k] = v
    return out


def assert_same(a, b):
    assert sorted(a) == sorted(b)
    for k in a:
        x, y = np.asarray(a[k]), np.asarray(b[k])
        assert x.dtype == y.dtype and x.shape == y.shape, k
        assert x.tobytes() == y.tobytes(), f"{k} differs"


def test_defaults_are_basalt_packs():
    """Every keyword default of basalt.pack.* is the C++ request's (which are basalt-pack's)."""
    want = _core.pack_defaults()
    for fn in (basalt.pack.box, basalt.pack.cylinder, basalt.pack.sphere, basalt.pack.mesh):
        params = inspect.signature(fn).parameters
        for name, value in want.items():
            if name in params:
                got = params[name].default
                if name == "seed":
                    got = str(got)
                elif name in ("origin", "centre"):  # basalt-pack's text of the vector
                    got = ",".join(f"{v:g}" for v in got)
                assert got == value, (fn.__name__, name, got, value)
        for required in ("rmin", "rmax"):
            assert params[required].default is inspect.Parameter.empty


def test_box_is_basalt_packs_bit_for_bit(bin_dir, tmp_path):
    cli_h5, cli_geo = tmp_path / "cli.h5", tmp_path / "cli.geo"
    args = ["box", "--size", "6,5,4", "--rmin", "0.25", "--rmax", "0.9", "--seed", "7"]
    p = run([bin_dir / "basalt-pack", *args, "-o", cli_h5])
    run([bin_dir / "basalt-pack", *args, "-q", "-o", cli_geo])

    g = basalt.pack.box(size=(6, 5, 4), rmin=0.25, rmax=0.9, seed=7)
    assert isinstance(g, basalt.Geometry) and g.n_particles > 100 and g.n_bonds > g.n_particles
    g.write(tmp_path / "py.h5")
    g.write(tmp_path / "py.geo")
    assert_same(h5_contents(cli_h5), h5_contents(tmp_path / "py.h5"))
    # .geo holds no provenance: the whole file is the same
    assert (tmp_path / "py.geo").read_bytes() == cli_geo.read_bytes()
    # the statistics basalt-pack prints
    assert f"particles            {g.pack_stats['particles']}\n" in p.stdout
    assert f"bonds                {g.pack_stats['bonds']}\n" in p.stdout
    assert f"solid fraction       {g.pack_stats['solid_fraction']:.4f}\n" in p.stdout
    assert g.pack_stats["volume"] in p.stdout
    assert g.attrs["command_line"] == "basalt.pack.box(size=(6, 5, 4), rmin=0.25, rmax=0.9, seed=7)"
    assert g.attrs["creator"].startswith(f"basalt-pack {basalt.__version__} (Python")


def test_threads_and_vector_text_change_nothing():
    a = basalt.pack.box(size=(4, 4, 4), rmin=0.3, rmax=0.8, seed=3, threads=1)
    b = basalt.pack.box(size="4,4,4", rmin=0.3, rmax=0.8, seed=3, threads=2)
    for k in a.particles:
        assert np.array_equal(a.particles[k], b.particles[k])
    assert np.array_equal(a.bonds["pairs"], b.bonds["pairs"])
    c = basalt.pack.box(size=(4, 4, 4), rmin=0.3, rmax=0.8, seed=4)
    assert not np.array_equal(a.positions[: len(c)], c.positions[: len(a)])


@pytest.mark.parametrize("shape, py, cli", [
    ("cylinder", dict(radius=3, height=4, origin=(1, 0, -1), exponent=2.2, fill=True, tag_layer="bottom:0.5:2"),
     ["--radius", "3", "--height", "4", "--origin", "1,0,-1", "--exponent", "2.2", "--fill",
      "--tag-layer", "bottom:0.5:2"]),
    ("sphere", dict(radius=2.5, center=(0, 0, 1), tag_layer=[("surface", 0.3, 5)], bond_tag=3),
     ["--radius", "2.5", "--center", "0,0,1", "--tag-layer", "surface:0.3:5", "--bond-tag", "3"]),
    ("box", dict(size=(8, 3, 3), lattice=True, no_bonds=True, seed=11),
     ["--size", "8,3,3", "--lattice", "--no-bonds", "--seed", "11"]),
])
def test_shapes_are_basalt_packs(bin_dir, tmp_path, shape, py, cli):
    run([bin_dir / "basalt-pack", shape, *cli, "--rmin", "0.3", "--rmax", "0.8", "-q", "-o", tmp_path / "cli.geo"])
    g = getattr(basalt.pack, shape)(rmin=0.3, rmax=0.8, **py)
    g.write(tmp_path / "py.geo")
    assert (tmp_path / "py.geo").read_bytes() == (tmp_path / "cli.geo").read_bytes()
    if "tag_layer" in py:
        assert len(np.unique(g.particles["tag"])) == 2
    if py.get("no_bonds"):
        assert g.n_bonds == 0


def test_mesh_is_basalt_packs(bin_dir, tmp_path):
    # a closed 4 x 4 x 3 box as an OFF mesh, outward triangles
    v = [(x, y, z) for x in (0, 4) for y in (0, 4) for z in (0, 3)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    off = tmp_path / "block.off"
    off.write_text("OFF\n8 12 0\n" + "".join(f"{x} {y} {z}\n" for x, y, z in v)
                   + "".join(f"3 {a} {b} {c}\n" for a, b, c in tris))
    run([bin_dir / "basalt-pack", "mesh", off, "--rmin", "0.3", "--rmax", "0.8", "-q", "-o", tmp_path / "cli.geo"])
    basalt.pack.mesh(off, rmin=0.3, rmax=0.8, output=tmp_path / "py.geo")
    assert (tmp_path / "py.geo").read_bytes() == (tmp_path / "cli.geo").read_bytes()


BAD = [
    (dict(size=(5, 5, 5), rmin=0.3, rmax=1, bond_tolerance=-1), ["--size", "5,5,5", "--rmin", "0.3", "--rmax", "1",
                                                                  "--bond-tolerance", "-1"]),
    (dict(size=(5, 5, 5), rmin=1, rmax=0.3), ["--size", "5,5,5", "--rmin", "1", "--rmax", "0.3"]),
    (dict(size=(5, 5, 5), rmin=0.3, rmax=1, seed=-1), ["--size", "5,5,5", "--rmin", "0.3", "--rmax", "1", "--seed=-1"]),
    (dict(size="5,5", rmin=0.3, rmax=1), ["--size", "5,5", "--rmin", "0.3", "--rmax", "1"]),
    (dict(size=(5, 5, 5), rmin=0.3, rmax=1, tag_layer="top:1:2"), ["--size", "5,5,5", "--rmin", "0.3", "--rmax", "1",
                                                                    "--tag-layer", "top:1:2"]),
    (dict(size=(5, 5, 5), rmin=0.3, rmax=1, exponent=25), ["--size", "5,5,5", "--rmin", "0.3", "--rmax", "1",
                                                            "--exponent", "25"]),
    (dict(size=(1e5, 1e5, 1e5), rmin=0.3, rmax=1), ["--size", "1e5,1e5,1e5", "--rmin", "0.3", "--rmax", "1"]),
    (dict(size=(1.2, 1.2, 1.2), rmin=0.5, rmax=0.5), ["--size", "1.2,1.2,1.2", "--rmin", "0.5", "--rmax", "0.5"]),
    (dict(size=(5, 5, 5), rmin=0.3, rmax=1, threads=0), ["--size", "5,5,5", "--rmin", "0.3", "--rmax", "1",
                                                          "--threads", "0"]),
    (dict(size=(5, 5, 5), rmin=float("nan"), rmax=1), ["--size", "5,5,5", "--rmin", "nan", "--rmax", "1"]),
]


@pytest.mark.parametrize("py, cli", BAD)
def test_impossible_requests_raise_basalt_packs_message(bin_dir, tmp_path, py, cli):
    p = run([bin_dir / "basalt-pack", "box", *cli, "-o", tmp_path / "x.h5"], check=False)
    assert p.returncode == 1 and p.stderr.startswith("basalt-pack: error: "), p.stderr
    message = p.stderr[len("basalt-pack: error: "):].rstrip("\n")
    with pytest.raises(basalt.PackError) as e:
        basalt.pack.box(**py)
    assert str(e.value) == message
    assert isinstance(e.value, ValueError)
    assert not list(tmp_path.iterdir())


def test_output_is_checked_before_packing_and_written(tmp_path):
    with pytest.raises(basalt.PackError, match="folder '.*nowhere' does not exist"):
        basalt.pack.box(size=(50, 50, 50), rmin=0.2, rmax=1, output=tmp_path / "nowhere" / "x.h5")
    with pytest.raises(basalt.PackError, match=r"unknown output format '\.txt'"):
        basalt.pack.box(size=(50, 50, 50), rmin=0.2, rmax=1, output=tmp_path / "x.txt")
    g = basalt.pack.sphere(radius=2, rmin=0.3, rmax=0.7, seed=2, output=tmp_path / "ball.h5", record_time=True)
    r = basalt.read_geometry(tmp_path / "ball.h5")
    assert np.array_equal(r.positions, g.positions) and np.array_equal(r.bonds["pairs"], g.bonds["pairs"])
    assert r.attrs["command_line"].startswith("basalt.pack.sphere(radius=2, rmin=0.3")
    assert "created" in r.attrs and r.statistics["pack_seconds"][0] > 0


def test_low_fraction_warns_when_allowed():
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        g = basalt.pack.box(size=(1.2, 1.2, 1.2), rmin=0.5, rmax=0.5, allow_low_fraction=True)
    assert g.n_particles == 1 and g.pack_stats["far_below"]
    assert len(w) == 1 and "far below the dense mode's 0.70" in str(w[0].message)


def test_arguments_are_checked_like_python_functions():
    with pytest.raises(TypeError, match="rmax"):
        basalt.pack.box(size=(5, 5, 5), rmin=0.3)
    with pytest.raises(TypeError):
        basalt.pack.box(size=(5, 5, 5), rmin=0.3, rmax=1, bond_tolerence=1e-5)  # misspelt
    with pytest.raises(TypeError):
        basalt.pack.sphere(radius=1, rmin=0.3, rmax=0.5, centre=(0, 0, 0), center=(0, 0, 0))
    with pytest.raises(TypeError, match=r"bins=16.5: a whole number expected"):
        basalt.pack.box(size=(5, 5, 5), rmin=0.3, rmax=1, bins=16.5)
    with pytest.raises(TypeError, match=r"rmin='small': a number expected"):
        basalt.pack.box(size=(5, 5, 5), rmin="small", rmax=1)
    assert "bond_tolerance" in basalt.pack.box.__doc__ and basalt.pack.box.__name__ == "box"
