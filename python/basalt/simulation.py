"""basalt.Simulation: a Basalt run driven from Python (docs/python.md).

    import basalt
    sim = basalt.Simulation("scenes/wave.toml", geometry="cube.h5", output="out/py")
    sim.run(1000)                                          # as basalt-run, checkpoints and fields.csv included
    sim.run(until=lambda s: s.kinetic_energy() < 1e-9, every=100, steps=50_000)   # a stage with a stop condition
    sim.walls["gate"].remove()                             # then take the gate away
    @sim.callback(every=100)
    def watch(s): print(s.step, s.walls["top"].force)

Run it as ``python3 script.py`` (one rank) or ``mpirun -np N python3 script.py``: every rank runs the same
script; the solver's calls are collective and must be made alike on every compute rank (decide on collective
values: kinetic_energy(), energies(), walls, sum()). With ``io_ranks=Q`` the last Q ranks write the output:
on them the constructor returns when the compute ranks close the run, with ``is_io_rank`` True.
"""

import numbers
import os
import warnings

from ._core_loader import core

_ARRAYS = ("x", "y", "z", "vx", "vy", "vz", "fx", "fy", "fz", "radius", "inv_mass", "id", "tag", "wx", "wy", "wz",
           "qw", "qx", "qy", "qz")


def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Real):
        return repr(float(v))
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(f"scene value {v!r}: not a TOML value (bool, number, string, list or dict)")


def scene_text(scene):
    """TOML text of a scene given as a dict: {"run": {...}, "walls": [{...}, ...], ...} (docs/scenes.md)."""
    lines = []
    for key, value in scene.items():
        if isinstance(value, dict):
            lines.append(f"[{key}]")
            lines += [f"{k} = {_toml_value(v)}" for k, v in value.items()]
        elif isinstance(value, (list, tuple)) and value and all(isinstance(t, dict) for t in value):
            for table in value:
                lines.append(f"[[{key}]]")
                lines += [f"{k} = {_toml_value(v)}" for k, v in table.items()]
        else:
            raise TypeError(f"scene key {key!r}: a table (dict) or an array of tables (list of dicts) expected")
        lines.append("")
    return "\n".join(lines)


class Particles:
    """This rank's owned particles as numpy views (no copy): sim.particles.x, .vz, .radius, .id, ...

    A view is valid until the next step (a rebuild reorders and reallocates the arrays): take it inside a
    callback or between runs, not across them. Writing velocities between steps changes the run; after
    writing positions call sim.state_changed().
    """

    def __init__(self, sim):
        self._sim = sim

    def __getattr__(self, name):
        if name in _ARRAYS:
            return self._sim._core.array(name)
        raise AttributeError(f"no particle array {name!r} (one of {', '.join(_ARRAYS)})")

    def __len__(self):
        return self._sim._core.owned

    @property
    def positions(self):
        """(N, 3) copy of the positions."""
        import numpy as np

        return np.column_stack([self.x, self.y, self.z])

    @property
    def velocities(self):
        import numpy as np

        return np.column_stack([self.vx, self.vy, self.vz])


class Wall:
    """A planar wall of the scene: position, normal and force (summed over the ranks), steering."""

    def __init__(self, sim, name):
        self._sim, self.name = sim, name

    def _state(self):
        return self._sim._core.walls()[self.name]

    @property
    def position(self):
        return self._state()["position"]

    @property
    def force(self):
        return self._state()["force"]

    @property
    def normal(self):
        return self._state()["normal"]

    @property
    def active(self):
        """Whether it touches particles (False for a wall removed, or declared with active = false)."""
        return not self._state()["removed"]

    def set_velocity(self, v):
        """Move at velocity v (3 numbers) from now on, from where the wall is."""
        self._sim._core.set_wall_velocity(self.name, [float(c) for c in v])

    def move_by(self, u):
        """Collective: moves the wall by u (3 numbers) now, and its motion on from there; the forces are recomputed
        (ESyS-Particle's moveWallBy)."""
        self._sim._core.move_wall_by(self.name, [float(c) for c in u])

    def stop(self):
        self.set_velocity((0.0, 0.0, 0.0))

    def set_motion(self, type, **keys):
        """Move from now on, from where the wall is, by a motion of the scene's walls[k].motion (docs/scenes.md),
        its times counting from now: set_motion("servo", target_force=5.0, gain=0.01, max_speed=0.5),
        set_motion("sine", amplitude=0.1, period=2.0), set_motion("ramp", velocity=(0, 0, -1), ramp_time=0.5)."""
        keys = dict(keys, type=type)
        self._sim._core.set_wall_motion(self.name, self._sim._keys_text(keys))

    def remove(self):
        """The wall touches no particle from now on (a gate taken away)."""
        self._sim._core.remove_wall(self.name)

    def add(self):
        """Collective: the wall touches particles from now on (one the scene declares with active = false, or one
        removed). Refused (basalt.InputError) when a particle's centre is behind it."""
        self._sim._core.add_wall(self.name)

    def __repr__(self):
        s = self._state()
        return f"Wall({self.name!r}, position={s['position']}, force={s['force']})"


class Walls:
    def __init__(self, sim):
        self._sim = sim

    def __getitem__(self, name):
        if name not in self._sim._core.walls():
            raise KeyError(f"no planar wall named {name!r} (the scene's walls: {', '.join(self) or 'none'})")
        return Wall(self._sim, name)

    def __iter__(self):
        return iter(self._sim._core.walls())

    def __len__(self):
        return len(self._sim._core.walls())


class Simulation:
    """A run: the scene (a file, TOML text or a dict), its geometry, its output (checkpoints, fields.csv)."""

    def __init__(self, scene, *, geometry=None, output=None, io_ranks=0, precision=None, checkpoint_every=None,
                 quiet=True, force_dt=False):
        if isinstance(scene, dict):
            # run.steps is basalt-run's; a script says how long with run(): 0 unless given
            scene = {**scene, "run": {"steps": 0, **scene.get("run", {})}} if "stages" not in scene else scene
            text, source = True, scene_text(scene)
        elif isinstance(scene, os.PathLike) or (isinstance(scene, str) and "\n" not in scene and "=" not in scene):
            text, source = False, os.fspath(scene)
        else:
            text, source = True, str(scene)
        # numpy now, not at the first view a callback takes: imported in the middle of a run it left the run
        # 10-15 % slower for the rest of it (measured on the wave, tools/bench/python_overhead.py)
        import numpy  # noqa: F401

        self._core = core().Simulation(
            source, text=text, geometry=os.fspath(geometry) if geometry else "",
            output=os.fspath(output) if output else "", io_ranks=int(io_ranks), precision=precision or "",
            checkpoint_every=-1 if checkpoint_every is None else int(checkpoint_every), quiet=bool(quiet),
            force_dt=bool(force_dt))
        self._callbacks = []  # (every, fn, reads velocities)
        self.particles = Particles(self)
        self.walls = Walls(self)
        self._warn_step()

    def _warn_step(self):
        # What the time step risks (dt above the safe fraction of the critical step, rot_bond networks above
        # 0.45 of it): basalt-run's warnings, as Python warnings, once per run (rank 0)
        if self._core.is_io_rank or self._core.rank != 0:
            return
        for text in self._core.step_warnings:
            warnings.warn(f"basalt.Simulation: {text}", RuntimeWarning, stacklevel=3)

    # -- running --------------------------------------------------------------------------------------------
    def run(self, steps=None, *, until=None, every=1):
        """Runs `steps` steps, or until `until(sim)` is true (checked every `every` steps; at most `steps`
        steps when both are given). Returns the steps made. Callbacks registered with callback() run too."""
        if steps is None and until is None:
            raise ValueError("run(): give steps, until, or both")
        if steps is None:
            steps = 2**62
        hooks = [(every_n, (lambda f: lambda step: f(self))(fn), velocities)
                 for every_n, fn, velocities in self._callbacks]
        if until is not None:
            hooks.append((int(every), lambda step: not until(self), True))
        return self._core.run(int(steps), hooks)

    def run_stages(self):
        """Runs the scene's [[stages]] in order (docs/scenes.md, "Stages"); returns one dict per stage: name,
        first_step, steps, condition_met, value (the condition's quantity at its end) and line (basalt-run's
        report line). Callbacks registered with callback() do not run during the stages."""
        return self._core.run_stages()

    def callback(self, fn=None, *, every=1, velocities=True):
        """Registers fn(sim) to run after every `every`-th step of each run (a decorator too). fn returning
        False ends the run. Returns fn. velocities=False: fn reads no velocities (positions, forces, walls
        only), so the step before it may leave its second half-kick to the next step (one pass over the
        particles fewer; the velocities fn would see are half a kick behind)."""
        def register(f):
            self._callbacks.append((int(every), f, bool(velocities)))
            return f
        return register(fn) if fn is not None else register

    def remove_callback(self, fn):
        self._callbacks = [c for c in self._callbacks if c[1] is not fn]

    # -- state ----------------------------------------------------------------------------------------------
    is_io_rank = property(lambda self: self._core.is_io_rank)
    rank = property(lambda self: self._core.rank, doc="this rank among the compute ranks (-1 on I/O ranks)")
    ranks = property(lambda self: self._core.ranks, doc="the number of compute ranks")
    step = property(lambda self: self._core.step)
    time = property(lambda self: self._core.time)
    total_particles = property(lambda self: self._core.total_particles)

    @property
    def dt(self):
        return self._core.dt

    @dt.setter
    def dt(self, value):
        """The time step from now on: refused (basalt.InputError, nothing changed) above the critical step unless
        the run is forced (force_dt=True, run.force_dt); warned of above the safe fraction."""
        self._core.set_dt(float(value))
        self._warn_step()

    def checkpoint(self):
        """Collective: writes a checkpoint of the current step now (out/ckpt_<step>.h5, as the scheduled ones; none
        when one of this step is written already). A restart from it is bit for bit when the scene writes
        checkpoints (output.checkpoint_every > 0: the run then keeps the positions of its last rebuild)."""
        self._core.checkpoint()

    @property
    def critical_dt(self):
        """The critical time step estimated at the start (docs/stability.md): sim.dt = 0.2 * sim.critical_dt sets
        dt as a fraction of it, as run.dt_fraction does."""
        return self._core.critical_dt

    def gather(self, name, everywhere=False):
        """Collective: one particle array (a name of sim.particles) of every rank, on rank 0 as (ids, values)
        sorted by id (float64 values); None on the other ranks, or the same on every rank with everywhere=True.
        A list of names gathers them in one exchange: values is then an (n, len(names)) array."""
        if isinstance(name, (list, tuple)):
            return self._core.gather_table([str(n) for n in name], bool(everywhere))
        return self._core.gather(name, bool(everywhere))

    def kinetic_energy(self):
        """Collective: the total kinetic energy (translation and rotation)."""
        return self._core.kinetic_energy()

    def energies(self):
        """Collective: the energy ledger's terms (kinetic, potentials, work, dissipated) summed over ranks."""
        return self._core.energies()

    def sum(self, value):
        """Collective: value summed over the compute ranks."""
        return self._core.allreduce(float(value), "sum")

    def max(self, value):
        return self._core.allreduce(float(value), "max")

    def min(self, value):
        return self._core.allreduce(float(value), "min")

    # -- steering ---------------------------------------------------------------------------------------------
    def fix(self, *tags):
        """Particles of these tags are held from now on (replaces the scene's particles.fixed_tags)."""
        self._core.set_fixed_tags([int(t) for t in tags])

    def free(self):
        """No particle is held from now on."""
        self._core.set_fixed_tags([])

    @property
    def body_forces(self):
        """The scene's [[body_forces]] groups: {name: model} (name: the group's name, e.g. "gravity0")."""
        return dict(self._core.body_forces())

    def set_body_force(self, name, **keys):
        """New keys for a body-force group from now on, checked as the scene's (docs/scenes.md):
        set_body_force("gravity0", acceleration=(0, 0, -2.0)). Keys not given take their defaults."""
        self._core.set_body_force(name, "\n".join(f"{k} = {_toml_value(v)}" for k, v in keys.items()))

    @property
    def contacts(self):
        """The scene's contact groups ([[interactions]] of a pair model): {name: model}, e.g. {"grains": "rot_friction"}
        (an unnamed group is "contacts<k>", k its index in [[interactions]])."""
        return dict(self._core.contacts())

    def set_contact(self, name, **keys):
        """Collective: new parameters for a contact group from now on, checked as the scene's (docs/scenes.md):
        set_contact("grains", K=1000.0, Ks=500.0, mu=0.2). Keys not given take their defaults; the group's tags
        and its contacts' history stay. Refused (nothing changed) when the new parameters make dt unstable or
        reach further than the lists were built for."""
        self._core.set_contact(name, self._keys_text(keys))

    def set_gravity(self, acceleration):
        """The scene's gravity (its one gravity group) from now on: set_gravity((0, 0, -9.81e-3))."""
        names = [n for n, m in self.body_forces.items() if m == "gravity"]
        if len(names) != 1:
            raise ValueError(f"set_gravity: the scene has {len(names)} gravity groups "
                             f"({', '.join(names) or 'none'}): use set_body_force(name, acceleration=...)")
        self.set_body_force(names[0], acceleration=[float(c) for c in acceleration])

    # -- particles in and out -----------------------------------------------------------------------------------
    def insert(self, *, count, radius, box=None, cylinder=None, velocity=None, tag=0, density=None, seed=1,
               attempts=20):
        """Collective: up to `count` new spheres now, where they overlap nothing, in a box ((x0, y0, z0), (x1, y1,
        z1)) or a cylinder dict(base=(x, y, z), axis=(0, 0, 1), radius=R, length=L); radius R or (rmin, rmax)
        (uniform). Returns how many went in (fewer when the region is full). The same keys as the scene's
        [[insert]] (docs/scenes.md); the same seed at the same step gives the same candidates."""
        keys = self._region_keys(box, cylinder)
        keys["radius"] = list(radius) if isinstance(radius, (list, tuple)) else float(radius)
        keys["count"] = int(count)
        if velocity is not None:
            keys["velocity"] = [float(c) for c in velocity]
        keys["tag"] = int(tag)
        if density is not None:
            keys["density"] = float(density)
        keys["seed"] = int(seed)
        keys["attempts"] = int(attempts)
        return self._core.insert(self._keys_text(keys))

    def delete(self, *, box=None, cylinder=None, tags=None):
        """Collective: removes the particles (of `tags`, or all) whose centre lies in the box or cylinder now,
        with their bonds; returns how many."""
        keys = self._region_keys(box, cylinder)
        if tags is not None:
            keys["tags"] = [int(t) for t in tags]
        return self._core.delete(self._keys_text(keys))

    @property
    def inserted(self):
        """Particles inserted so far in this process's run (the scene's [[insert]] and insert() calls)."""
        return self._core.flow_totals()[0]

    @property
    def deleted(self):
        """Particles removed so far in this process's run (the scene's [[delete]] and delete() calls)."""
        return self._core.flow_totals()[1]

    def bond_count(self):
        """Collective: the bonds now."""
        return self._core.bond_count()

    def broken_bond_pairs(self):
        """Collective: the bonds broken so far as an (n, 3) int64 array, on every rank: their particles' ids
        (the smaller first) and the step each broke at, sorted."""
        return self._core.broken_bond_pairs()

    def broken_bonds(self):
        """Collective: the bonds broken so far."""
        return self._core.broken_bonds()

    def saved_field(self, name):
        """Collective: the value the scene's [[output.fields]] saver of column `name` (a fields.csv column, e.g.
        "bond_potential_energy") computed at this step, summed over the compute ranks, as fields.csv holds it;
        None when that saver was not due at this step. KeyError when no saver has that column."""
        return self._core.saved_field(name)

    @staticmethod
    def _region_keys(box, cylinder):
        if (box is None) == (cylinder is None):
            raise ValueError("give the region as box=((x0, y0, z0), (x1, y1, z1)) or "
                             "cylinder=dict(base=..., axis=..., radius=..., length=...)")
        if box is not None:
            lo, hi = box
            return {"box": {"min": [float(c) for c in lo], "max": [float(c) for c in hi]}}
        return {"cylinder": dict(cylinder)}

    @staticmethod
    def _keys_text(keys):
        return "\n".join(f"{k} = {_toml_value(v)}" for k, v in keys.items())

    def state_changed(self):
        """Collective: call after writing positions (recomputes forces and the energy the guard starts from)."""
        self._core.state_changed()

    def close(self):
        """Ends the run's output (collective: the I/O ranks finish writing). Raises on an output error."""
        error = self._core.close()
        if error:
            raise RuntimeError(f"output failed: {error}")

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        error = self._core.close()
        if error and exc[0] is None:
            raise RuntimeError(f"output failed: {error}")
        return False
