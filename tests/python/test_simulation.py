"""basalt.Simulation: a run driven from Python is basalt-run's run (same bits), hooks run at their steps and can
end a run, exceptions in them end it with their own type, steering (walls, dt, fixed tags, velocities) acts,
and 2 compute ranks plus an I/O rank work from one script (mpirun)."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import basalt

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("BASALT_BIN", ROOT / "build" / "bin"))
CUBE = ROOT / "tests" / "data" / "cube1.geo"


def wave_scene(out, steps=200, checkpoint_every=100):
    """The wave benchmark's physics on the GenGeo cube, short."""
    return {
        "units": {"length": "mm", "time": "ms", "force": "N"},
        "geometry": {"file": str(CUBE)},
        "material": {"density": 1.0},
        "run": {"dt": 1.0e-3, "steps": steps, "skin": 0.1},
        "interactions": [
            {"name": "bonds", "type": "linear_bond", "K": 1000.0, "rest_length": "initial_distance"},
            {"name": "contacts", "type": "linear_elastic", "K": 1000.0},
        ],
        "walls": [{"name": "base", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0], "K": 1000.0,
                   "stiffness": "plain", "motion": {"type": "half_sine", "amplitude": 0.1, "period": 1.0}}],
        "output": {"directory": str(out), "checkpoint_every": checkpoint_every,
                   "fields": [{"type": "kinetic_energy", "every": 10}]},
    }


def pile_scene(out):
    """Spheres in a box of walls under gravity, with friction; the 'gate' wall holds them at x < 6."""
    return {
        "geometry": {"file": str(out / "pile.h5")},
        "particles": {"rotation": True},
        "run": {"dt": 2e-3, "steps": 0, "skin": 0.1},
        "interactions": [{"type": "rot_friction", "K": 1000.0, "Ks": 500.0, "mu": 0.5, "mu_dynamic": 0.4}],
        "walls": [
            {"name": "floor", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0], "K": 1000.0},
            {"name": "back", "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0], "K": 1000.0},
            {"name": "gate", "point": [6.0, 0.0, 0.0], "normal": [-1.0, 0.0, 0.0], "K": 1000.0},
            {"name": "front", "point": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0], "K": 1000.0},
            {"name": "rear", "point": [0.0, 6.0, 0.0], "normal": [0.0, -1.0, 0.0], "K": 1000.0},
        ],
        "body_forces": [{"type": "gravity", "acceleration": [0.0, 0.0, -1.0]},
                        {"type": "linear_damping", "viscosity": 0.2},
                        {"type": "rotational_damping", "viscosity": 0.2}],
        "output": {"directory": str(out / "run")},
    }


def pack_pile(out):
    basalt.pack.box(size=(6, 6, 6), rmin=0.4, rmax=0.5, seed=5, no_bonds=True).write(out / "pile.h5")


def h5(path):
    import h5py

    with h5py.File(path, "r") as f:
        return {k: f["particles"][k][()] for k in f["particles"]}


def test_python_run_is_basalt_runs_run(tmp_path):
    """200 steps from Python and from basalt-run on the same scene: the checkpoints' particle data and the
    field series are identical."""
    import tomllib

    scene = wave_scene(tmp_path / "py")
    with basalt.Simulation(scene) as sim:
        assert sim.run(200) == 200
        assert sim.step == 200 and sim.time == pytest.approx(0.2)
        assert sim.total_particles == 8948
    text = basalt.simulation.scene_text(wave_scene(tmp_path / "cli"))
    assert tomllib.loads(text)["walls"][0]["motion"]["type"] == "half_sine"
    (tmp_path / "cli.toml").write_text(text)
    subprocess.run([str(BIN / "basalt-run"), str(tmp_path / "cli.toml"), "--quiet"], check=True,
                   capture_output=True)
    a, b = h5(tmp_path / "py" / "ckpt_000200.h5"), h5(tmp_path / "cli" / "ckpt_000200.h5")
    assert a.keys() == b.keys() and "position" in a
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)
    assert (tmp_path / "py" / "fields.csv").read_text() == (tmp_path / "cli" / "fields.csv").read_text()


def test_callbacks_until_and_exceptions(tmp_path):
    scene = wave_scene(tmp_path / "cb", checkpoint_every=0)
    sim = basalt.Simulation(scene)
    seen = []
    sim.callback(lambda s: seen.append((s.step, s.particles.vz.copy())), every=25)
    assert sim.run(100) == 100
    assert [s for s, _ in seen] == [25, 50, 75, 100]
    assert seen[-1][1].shape == (sim.particles.__len__(),)
    # a stop condition ends the run at the first check where it holds
    n = sim.run(until=lambda s: s.step >= 130, every=10, steps=1000)
    assert n == 30 and sim.step == 130
    # a callback returning False ends the run too
    sim.callback(lambda s: s.step < 150, every=5)
    assert sim.run(1000) == 20
    # an exception in a callback ends the run with its own type and message
    sim._callbacks.clear()

    def boom(s):
        raise ValueError(f"boom at {s.step}")

    sim.callback(boom, every=7)
    with pytest.raises(ValueError, match="boom at 154"):  # 154 = 22 x 7
        sim.run(100)
    sim.close()
    with pytest.raises(basalt.RunError, match="closed"):
        sim.run(10)


def test_views_and_steering(tmp_path):
    pack_pile(tmp_path)
    sim = basalt.Simulation(pile_scene(tmp_path))
    x = sim.particles.x
    assert x.flags.writeable and not x.flags.owndata and x.base is not None  # a view, not a copy
    sim.run(until=lambda s: s.kinetic_energy() < 1e-3, every=100, steps=20000)
    settled = sim.step
    assert settled < 20000
    assert sim.particles.x.max() < 6.0
    gate = sim.walls["gate"]
    assert gate.force[0] > 0  # the pile leans on the gate (its normal points to -x)
    with pytest.raises(KeyError, match="gate"):
        sim.walls["no such wall"]
    gate.remove()
    sim.run(2000)
    assert sim.particles.x.max() > 6.5  # the pile runs out past where the gate was
    assert sim.walls["gate"].force == (0.0, 0.0, 0.0)
    assert not sim.walls["gate"].active
    with pytest.raises(basalt.InputError, match='wall "gate" cannot be added: .* behind it'):
        sim.walls["gate"].add()  # the pile is past it now
    assert not sim.walls["gate"].active
    # steering: a wall moves at the velocity it is given; dt; velocities written between steps
    floor = sim.walls["floor"]
    z0 = floor.position[2]
    floor.set_velocity((0, 0, 0.01))
    sim.run(100)
    assert floor.position[2] - z0 == pytest.approx(0.01 * 100 * sim.dt)
    floor.stop()
    rear = sim.walls["rear"]  # any motion of the scene's, its clock starting now
    y0 = rear.position[1]
    rear.set_motion("constant_velocity", velocity=(0.0, -0.01, 0.0))
    sim.run(100)
    assert rear.position[1] - y0 == pytest.approx(-0.01 * 100 * sim.dt)
    with pytest.raises(basalt.InputError, match="type"):
        rear.set_motion("wobble")
    rear.stop()
    assert 2e-3 < sim.critical_dt < 1.0  # the scene's dt = 2e-3 runs below its critical step
    sim.dt = 1e-3
    assert sim.dt == 1e-3
    with pytest.raises(ValueError, match="positive"):
        sim.dt = -1
    # above the critical step: refused, nothing changed; just below it: taken with a warning (rank 0)
    with pytest.raises(basalt.InputError, match="times the critical time step"):
        sim.dt = 1.05 * sim.critical_dt
    assert sim.dt == 1e-3
    with pytest.warns(RuntimeWarning, match="above the safe fraction"):
        sim.dt = 0.95 * sim.critical_dt
    sim.dt = 1e-3
    # body forces: the scene's groups by name; gravity changed from now on; bad keys named
    assert sim.body_forces["gravity0"] == "gravity"
    sim.set_gravity((0.0, 0.0, -2.0))
    with pytest.raises(basalt.InputError, match="speed"):
        sim.set_body_force("gravity0", acceleration=(0, 0, -1), speed=3)
    with pytest.raises(basalt.InputError, match="no body force named"):
        sim.set_body_force("nope", acceleration=(0, 0, -1))
    # contact groups: new parameters from now on; an unstable stiffness refused, naming the group
    assert sim.contacts == {"contacts0": "rot_friction"}
    e = sim.energies()["contact_potential_energy"]
    sim.set_contact("contacts0", K=1000.0, Ks=500.0, mu=0.1, mu_dynamic=0.1)
    with pytest.raises(basalt.InputError, match='interactions "contacts0".*critical time step'):
        sim.set_contact("contacts0", K=1e12, Ks=500.0, mu=0.1)
    with pytest.raises(basalt.InputError, match="contact groups: contacts0"):
        sim.set_contact("grains", K=1.0)
    assert sim.energies()["contact_potential_energy"] == e  # normal energy: K unchanged
    vz = sim.particles.vz
    vz[:] = 0.0
    vz[0] = 5.0
    sim.run(1)
    assert sim.particles.vz.max() > 4.0  # the write took (one step of gravity and contacts later)
    sim.close()


def test_bad_scene_is_a_python_exception(tmp_path):
    scene = wave_scene(tmp_path / "bad")
    scene["run"]["dt"] = -1.0
    with pytest.raises(ValueError, match="dt"):
        basalt.Simulation(scene)
    with pytest.raises(ValueError, match="does not exist"):
        basalt.Simulation(wave_scene(tmp_path / "bad"), geometry=tmp_path / "missing.h5")


def test_a_step_above_the_safe_fraction_is_warned_of(tmp_path):
    """basalt-run's warnings on the time step reach a script as RuntimeWarnings; none at a safe step."""
    scene = wave_scene(tmp_path / "a", steps=0)
    critical = basalt.Simulation(scene).critical_dt
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        basalt.Simulation(scene)  # dt = 1e-3: no warning
    scene["run"]["dt"] = 0.9 * critical
    with pytest.warns(RuntimeWarning, match="above the safe fraction"):
        basalt.Simulation(scene)


def test_units_other_than_the_geometrys_are_warned_of(tmp_path, capfd):
    """The start-up is basalt-run's (solver/app/run_start.hpp): the same warning, on stderr."""
    scene = wave_scene(tmp_path / "units", checkpoint_every=0)
    scene["units"]["length"] = "m"
    with basalt.Simulation(scene):
        pass
    assert "warning: the geometry declares units mm, ms, N; the scene m, ms, N" in capfd.readouterr().err


@pytest.mark.skipif(not (BIN / "basalt-run").exists(), reason="needs the build's basalt-run")
def test_mpi_two_compute_ranks_and_an_io_rank(tmp_path):
    """mpirun -np 3 python3 script.py with io_ranks=1: the I/O rank writes the checkpoint; the two compute
    ranks' run is the one-rank run's to rounding (the wave is decomposition-invariant to 1e-9 or better)."""
    script = tmp_path / "run.py"
    script.write_text(textwrap.dedent(f"""
        import sys, basalt
        sys.path.insert(0, {str(Path(__file__).parent)!r})
        from test_simulation import wave_scene
        from pathlib import Path
        sim = basalt.Simulation(wave_scene(Path({str(tmp_path)!r}) / "mpi"), io_ranks=1)
        if not sim.is_io_rank:
            steps = []
            sim.callback(lambda s: steps.append(s.step), every=50)
            sim.run(200)
            ke = sim.kinetic_energy()
            assert steps == [50, 100, 150, 200], steps
            g = sim.gather("z")
            if sim.rank == 0:
                ids, z = g
                assert len(ids) == 8948 and (ids[1:] > ids[:-1]).all(), len(ids)
            else:
                assert g is None
            ids, z = sim.gather("z", everywhere=True)  # every rank's particles on every rank
            assert len(ids) == 8948 and (ids[1:] > ids[:-1]).all(), len(ids)
            ids2, table = sim.gather(["x", "z"], everywhere=True)  # several arrays in one exchange
            assert (ids2 == ids).all() and table.shape == (8948, 2) and (table[:, 1] == z).all()
            assert (table[:, 0] == sim.gather("x", everywhere=True)[1]).all()
            if sim.rank == 0:
                assert (ids == g[0]).all() and (z == g[1]).all()
                print("ranks", sim.ranks, "ke", repr(ke))
        sim.close()
    """))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    r = subprocess.run(["mpirun", "-np", "3", sys.executable, str(script)], env=env, capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "ranks 2" in r.stdout
    a, b = h5(tmp_path / "mpi" / "ckpt_000200.h5"), None
    with basalt.Simulation(wave_scene(tmp_path / "one")) as sim:
        sim.run(200)
    b = h5(tmp_path / "one" / "ckpt_000200.h5")
    ia, ib = np.argsort(a["id"]), np.argsort(b["id"])
    np.testing.assert_allclose(a["position"][ia], b["position"][ib], rtol=0, atol=1e-9)


@pytest.mark.skipif(not (BIN / "basalt-run").exists(), reason="needs the build's basalt-run")
def test_checkpoint_now_is_a_restart_point(tmp_path):
    """sim.checkpoint() between runs writes the current step's checkpoint; basalt-run restarted from it reaches
    the scheduled checkpoint 50 steps on with the particles of the Python run, to the bit."""
    scene = wave_scene(tmp_path / "py", steps=100, checkpoint_every=100)
    with basalt.Simulation(scene) as sim:
        sim.run(50)
        sim.checkpoint()
        sim.checkpoint()  # the same step again: nothing more
        sim.run(50)
    assert (tmp_path / "py" / "ckpt_000050.h5").exists()
    import h5py

    with h5py.File(tmp_path / "py" / "ckpt_000050.h5", "r") as f:  # the scene as the run read it
        stored = f.attrs["scene_text"]
    text = tmp_path / "wave.toml"
    text.write_text(stored.decode() if isinstance(stored, bytes) else str(stored))
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    r = subprocess.run([str(BIN / "basalt-run"), str(text), "--restart", str(tmp_path / "py" / "ckpt_000050.h5"),
                        "--steps", "50", "--output", str(tmp_path / "cli"), "--quiet"], env=env,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    a, b = h5(tmp_path / "py" / "ckpt_000100.h5"), h5(tmp_path / "cli" / "ckpt_000100.h5")
    np.testing.assert_array_equal(a["id"], b["id"])
    np.testing.assert_array_equal(a["position"], b["position"])
    np.testing.assert_array_equal(a["velocity"], b["velocity"])
