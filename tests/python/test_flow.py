"""Particles in and out from Python (Simulation.insert / delete, the scene's [[insert]] / [[delete]]): the
newcomers overlap nothing and get new ids, deletion takes exactly the region's particles, the counts follow,
bad requests are Python exceptions, and checkpoints keep the id counter."""

from pathlib import Path

import numpy as np
import pytest

import basalt
from test_simulation import h5, pile_scene


def pack_bed(out):
    basalt.pack.box(size=(6, 6, 3), rmin=0.4, rmax=0.5, seed=5, no_bonds=True).write(out / "pile.h5")


def overlap_of_new(ids, pos, rad, first):
    """The deepest overlap (over the smaller radius) of a particle with id >= first with any other."""
    new = ids >= first
    worst = 0.0
    for k in np.nonzero(new)[0]:
        d = np.linalg.norm(pos - pos[k], axis=1)
        d[k] = np.inf
        worst = max(worst, float(np.max((rad + rad[k] - d) / np.minimum(rad, rad[k]))))
    return worst


def test_insert_then_delete(tmp_path):
    pack_bed(tmp_path)
    with basalt.Simulation(pile_scene(tmp_path)) as sim:
        n0 = sim.total_particles
        first = int(sim.gather("id")[0].max()) + 1
        n = sim.insert(box=((0.5, 0.5, 4.0), (5.5, 5.5, 8.0)), radius=(0.4, 0.5), count=60, velocity=(0, 0, -1),
                       tag=4, seed=2)
        assert 20 < n <= 60
        assert sim.total_particles == n0 + n and sim.inserted == n
        ids, x = sim.gather("x")
        _, y = sim.gather("y")
        _, z = sim.gather("z")
        _, r = sim.gather("radius")
        _, tag = sim.gather("tag")
        _, vz = sim.gather("vz")
        assert len(np.unique(ids)) == len(ids) == n0 + n
        assert sorted(ids[ids >= first]) == list(range(first, first + n))
        pos = np.column_stack([x, y, z])
        assert overlap_of_new(ids, pos, r, first) <= 0.0
        newc = ids >= first
        assert (tag[newc] == 4).all() and (vz[newc] == -1.0).all()
        assert (z[newc] - r[newc] >= 4.0).all() and (z[newc] + r[newc] <= 8.0).all()
        sim.run(500)  # they fall onto the bed; nothing is lost, the energy guard holds
        assert sim.total_particles == n0 + n
        # Deletion takes exactly the particles whose centre is in the region.
        ids, x = sim.gather("x")
        want = int(np.sum(x < 3.0))
        got = sim.delete(box=((-1.0, -1.0, -1.0), (3.0, 7.0, 20.0)))
        assert got == want and sim.deleted == want
        assert sim.total_particles == n0 + n - want
        assert (sim.gather("x")[1] >= 3.0).all()
        sim.run(100)
        assert sim.total_particles == n0 + n - want


def test_bad_requests_are_python_exceptions(tmp_path):
    pack_bed(tmp_path)
    with basalt.Simulation(pile_scene(tmp_path)) as sim:
        n0 = sim.total_particles
        with pytest.raises(ValueError, match="exceeds the largest radius"):
            sim.insert(box=((0, 0, 4), (6, 6, 8)), radius=0.9, count=3)
        with pytest.raises(ValueError, match="box or cylinder|give the region"):
            sim.insert(radius=0.4, count=3)
        with pytest.raises(ValueError, match="insert.radius"):
            sim.insert(box=((0, 0, 4), (0.5, 6, 8)), radius=0.4, count=3)  # no room for a sphere
        assert sim.total_particles == n0


def test_a_count_zero_insert_declares_the_radii_a_script_pours(tmp_path):
    """[[insert]] with count = 0 makes no events but lets insert() bring spheres larger than the geometry's."""
    pack_bed(tmp_path)
    scene = pile_scene(tmp_path)
    scene["insert"] = [{"name": "declared", "box": {"min": [0.0, 0.0, 4.0], "max": [6.0, 6.0, 9.0]},
                        "radius": [0.4, 0.9], "count": 0}]
    with basalt.Simulation(scene) as sim:
        n0 = sim.total_particles
        sim.run(200)
        assert sim.total_particles == n0 and sim.inserted == 0  # no events of its own
        assert sim.insert(box=((0, 0, 4), (6, 6, 9)), radius=0.9, count=3, seed=3) == 3
        with pytest.raises(ValueError, match="exceeds the largest radius"):
            sim.insert(box=((0, 0, 4), (6, 6, 9)), radius=0.95, count=1)
        sim.run(200)
        assert sim.total_particles == n0 + 3


def test_scene_pour_keeps_its_id_counter(tmp_path):
    """The scene's [[insert]] every 50 steps and [[delete]] at the floor: the checkpoint keeps the counter,
    and its ids are unique."""
    pack_bed(tmp_path)
    scene = pile_scene(tmp_path)
    scene["insert"] = [{"cylinder": {"base": [3.0, 3.0, 5.0], "axis": [0.0, 0.0, 1.0], "radius": 2.5,
                                     "length": 3.0}, "radius": [0.3, 0.45], "count": 15, "every": 50, "tag": 2}]
    scene["delete"] = [{"box": {"min": [-1.0, -1.0, -1.0], "max": [7.0, 7.0, 0.6]}, "every": 100, "tags": [0]}]
    scene["output"]["checkpoint_every"] = 200
    with basalt.Simulation(scene) as sim:
        n0 = sim.total_particles
        sim.run(1)
        assert sim.inserted == 15  # the event at step 0: an empty region takes all
        sim.run(199)
        assert 15 < sim.inserted <= 60  # events at steps 50, 100, 150 into what is still falling
        assert sim.total_particles == n0 + sim.inserted - sim.deleted
        total = sim.total_particles
    import h5py

    with h5py.File(tmp_path / "run" / "ckpt_000200.h5", "r") as f:
        nxt = int(f.attrs["next_particle_id"])
    p = h5(tmp_path / "run" / "ckpt_000200.h5")
    assert len(p["id"]) == total and len(np.unique(p["id"])) == total
    assert nxt == p["id"][p["tag"] == 2].max() + 1
