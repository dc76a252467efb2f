"""LsmMpi: ESyS-Particle's simulation object, on top of basalt.Simulation (docs/esys.md).

The set-up calls collect the scene (particles, interaction groups, walls, savers); the first run() or
runTimeStep() starts a basalt.Simulation from it, with ESyS's conventions: symplectic Euler, masses as given,
ESyS's scalings (NRotElastic, walls pi r K), ESyS's damping rule, no start-up checks ESyS does not make.
Runnables, field savers and checkpointers run at ESyS's points of the step (docs/reference-runs.md)."""

import atexit
import math
import shutil
import tempfile

from .errors import refuse
from .output import CheckPointer, FieldSaver
from .particles import NRotSphere, RotSphere
from .vec3 import Vec3


_HINTS = {
    "setParticleDensity": "give each NRotSphere/RotSphere its mass (mass=...), as the tutorial's scripts do",
    "setVelocityOfWall": "in ESyS-Particle it sets the velocity a viscous wall interaction (ViscWallPrms) reads and "
                         "never moves the wall (ESyS's TSubLattice::setVelocityOfWall; 2.3.5 hangs on it for an "
                         "elastic wall, measured); to move a wall at constant velocity call moveWallBy from a "
                         "Runnable (each step's displacement), or use basalt.Simulation's walls[name].set_velocity",
    "setParticleNonDynamic": "the scene's particles.fixed_tags or basalt.Simulation.fix(tag)",
    "setParticleNonRotational": "NRotSphere particles",
    "createSphereBody": "Basalt's planar and mesh walls (docs/scenes.md)",
    "loadCheckPoint": "basalt-run --restart with Basalt's HDF5 checkpoints",
    "setVerbosity": "nothing: Basalt's front end prints no log",
}


class LsmMpi:
    """LsmMpi(numWorkerProcesses, mpiDimList): the simulation. Basalt runs it on the ranks mpirun starts (one
    without mpirun), every one a compute rank with Basalt's own decomposition; numWorkerProcesses and mpiDimList
    are accepted and not needed. Every rank runs the script; the particles the script sees (getParticleList)
    are every rank's, gathered on each; rank 0 alone writes the savers' and checkpoints' files."""

    def __init__(self, numWorkerProcesses=1, mpiDimList=None):
        from . import world

        self._root = world()[0] == 0
        self.numWorkerProcesses, self.mpiDimList = int(numWorkerProcesses), list(mpiDimList or [1, 1, 1])
        self._particle_type = None
        self._verlet = None
        self._dt = None
        self._num_steps = 0
        self._domain_lo = self._domain_hi = None
        self._particles = []            # NRotSphere/RotSphere as created
        self._pair = []                 # NRotElasticPrms
        self._bond_groups = []          # NRotBondPrms
        self._bonds = []                # (id1, id2, tag) from createConnections
        self._wall_k = {}               # wall name -> NRotElasticWallPrms or NRotBondedWallPrms
        self._moved_before = set()      # walls moveWallBy moved before the run
        self._meshes = {}               # mesh name -> (vertices, triangles) from readMesh, in reading order
        self._mesh_k = {}               # mesh name -> NRotElasticTriMeshPrms
        self._walls = {}                # name -> (posn, normal), in creation order
        self._body = []                 # GravityPrms, LinDampingPrms
        self._group_names = set()
        self._exclusions = set()        # (bond group name, contact group name) from createExclusion
        self._savers, self._checkpointers = [], []
        self._pre, self._post = [], []
        self._sim = None
        self._dir = None
        self._t = 0                     # steps completed
        self._clock = 0                 # what getTimeStep() returns (t + 1 inside pre-time-step runnables)
        self._saved = -1                # the last step whose savers ran
        self._watching = False          # ESyS's neighbour-list rule and domain watched (esys_watch.hpp)
        self._prev_force = None         # (ids, forces) the last step used (ESyS's stored force)
        self._prev_wall_force = {}      # wall name -> the force the last step's particles got from it
        self._prev_bond_energy = 0.0    # the bonds' potential energy of the last step's forces (ESyS's saver)
        self._rotational = False

    # -- set-up ---------------------------------------------------------------------------------------------
    def initNeighbourSearch(self, particleType, gridSpacing, verletDist):
        if particleType not in ("NRotSphere", "RotSphere"):
            refuse(f"LsmMpi.initNeighbourSearch(particleType={particleType!r})",
                   "NRotSphere and RotSphere are supported")
        self._particle_type, self._grid, self._verlet = particleType, float(gridSpacing), float(verletDist)
        self._rotational = particleType == "RotSphere"

    def setSpatialDomain(self, bBox, circDimList=None):
        if circDimList and any(circDimList):
            refuse("LsmMpi.setSpatialDomain(circDimList=...)", "Basalt scenes have periodic boundaries "
                   "(basalt.Simulation, docs/scenes.md); the front end does not map them yet")
        self._domain_lo, self._domain_hi = bBox.getMinPt().toTuple(), bBox.getMaxPt().toTuple()

    def setTimeStepSize(self, dt):
        self._dt = float(dt)
        if self._sim is not None:
            self._sim.dt = self._dt

    def getTimeStepSize(self):
        return self._dt

    def setNumTimeSteps(self, numTimeSteps):
        self._num_steps = int(numTimeSteps)

    def getNumTimeSteps(self):
        return self._num_steps

    def getTimeStep(self):
        return self._clock

    def force2dComputations(self, do2d=True):
        if do2d:
            refuse("LsmMpi.force2dComputations(True)", "Basalt runs 3-D only")

    def _setup(self, call):
        if self._sim is not None:
            refuse(f"LsmMpi.{call} after the run started",
                   "Basalt's scene is fixed once it runs; basalt.Simulation inserts particles (insert) and "
                   "steers walls between runs")

    def createParticle(self, particle):
        """An NRotSphere/RotSphere, or a generated SimpleSphere (CubicBlock, RandomBoxPacker: ESyS's createParticle
        is createParticles of one): a particle of the run's type with the sphere's id, tag, radius and mass."""
        from .blocks import SimpleSphere

        self._setup("createParticle")
        if isinstance(particle, SimpleSphere) and self._particle_type is not None:
            kind = RotSphere if self._particle_type == "RotSphere" else NRotSphere
            q = kind(particle.getId(), particle.getPosn(), particle.getRadius(), particle.getMass())
            q.setTag(particle.getTag())
            particle = q
        if not isinstance(particle, NRotSphere):
            raise TypeError(f"LsmMpi.createParticle: an NRotSphere or RotSphere, got {type(particle).__name__}")
        want = RotSphere if self._particle_type == "RotSphere" else NRotSphere
        if self._particle_type is None:
            raise ValueError("LsmMpi.createParticle before initNeighbourSearch(particleType=...)")
        if type(particle) is not want:
            raise TypeError(f"LsmMpi.createParticle: a {type(particle).__name__} in a {self._particle_type} run "
                            "(initNeighbourSearch's particleType)")
        if particle.getMass() <= 0.0:
            raise ValueError(f"LsmMpi.createParticle: particle {particle.getId()} has mass {particle.getMass()}")
        self._particles.append(particle)

    def createParticles(self, particles):
        """NRotSphere/RotSphere objects, or a generated block's SimpleSpheres (CubicBlock): each becomes a
        particle of the run's type with the sphere's id, tag, radius and mass (r^3, as ESyS)."""
        for p in particles:
            self.createParticle(p)

    def readGeometry(self, fileName):
        """An ESyS .geo file (LSMGeometry, as GenGeo writes it; Basalt's reader): each sphere a particle of the run's
        type with its id, tag, radius and mass 4/3 pi r^3 (ESyS's GeometryReader, 3-D), the file's bonds as
        connections with their tags; the file's bounding box becomes the spatial domain unless one was set (as
        ESyS: a set domain is kept)."""
        from ..geometry import read_geometry

        self._setup("readGeometry")
        if self._particle_type is None:
            raise ValueError("LsmMpi.readGeometry before initNeighbourSearch(particleType=...)")
        from . import before_read

        before_read(fileName)  # under mpirun: after rank 0 wrote it, when the script did
        g = read_geometry(str(fileName))
        if any(g.periodic) and self._domain_lo is None:
            refuse(f"LsmMpi.readGeometry({fileName!r}): a geometry with periodic boundaries",
                   "Basalt scenes have periodic boundaries (basalt.Simulation, docs/scenes.md); the front end "
                   "does not map them yet")
        if self._domain_lo is None:
            self._domain_lo, self._domain_hi = tuple(g.box_min.tolist()), tuple(g.box_max.tolist())
        kind = RotSphere if self._rotational else NRotSphere
        part = g.particles
        for pid, x, r, tag in zip(part["id"].tolist(), part["position"].tolist(), part["radius"].tolist(),
                                  part["tag"].tolist()):
            p = kind(pid, Vec3(*x), r, (math.pi * r * r) * ((4.0 / 3.0) * r))  # ESyS's order of operations
            p.setTag(tag)
            self.createParticle(p)
        for (i, j), t in zip(g.bonds["pairs"].tolist(), g.bonds["tag"].tolist()):
            self._bonds.append((min(i, j), max(i, j), int(t)))

    def createConnections(self, connections):
        """Bonds (ConnectionFinder's, or objects with getId1, getId2, getTag) for NRotBondPrms groups."""
        self._setup("createConnections")
        for c in connections:
            i, j = int(c.getId1()), int(c.getId2())
            self._bonds.append((min(i, j), max(i, j), int(c.getTag())))

    def _name(self, prms):
        if prms.name in self._group_names:
            raise ValueError(f"LsmMpi.createInteractionGroup: a group named {prms.name!r} exists")
        self._group_names.add(prms.name)

    def createInteractionGroup(self, prms):
        from . import prms as P

        self._setup("createInteractionGroup")
        kind = type(prms).__name__
        if isinstance(prms, (P.NRotElasticPrms, P.RotFrictionPrms, P.NRotFrictionPrms)):
            if self._pair:
                refuse(f"LsmMpi.createInteractionGroup({kind}): a second contact group (with "
                       f"{type(self._pair[0]).__name__} {self._pair[0].name!r})",
                       "one contact group (NRotElastic, RotFriction, FrictionPrms or NRotFriction) per run")
            if isinstance(prms, P.RotFrictionPrms):
                if not self._rotational:
                    raise ValueError(f"LsmMpi.createInteractionGroup({kind}): RotFriction acts between RotSpheres "
                                     "(initNeighbourSearch(particleType=\"RotSphere\", ...))")
                if prms.scaling and not prms.meanR_scaling:
                    refuse(f"LsmMpi.createInteractionGroup({kind}(meanR_scaling=False))",
                           "Basalt's rot_friction scales by the mean radius (meanR_scaling=True)")
                if prms.dynamicMu > prms.staticMu:
                    refuse(f"LsmMpi.createInteractionGroup({kind}): dynamicMu {prms.dynamicMu} > staticMu "
                           f"{prms.staticMu}", "Basalt's rot_friction needs mu_dynamic <= mu")
            self._name(prms)
            self._pair.append(prms)
        elif isinstance(prms, (P.NRotBondPrms, P.RotBondPrms, P.BrittleBeamPrms)):
            if not isinstance(prms, P.NRotBondPrms) and not self._rotational:
                raise ValueError(f"LsmMpi.createInteractionGroup({kind}): rotational bonds join RotSpheres "
                                 "(initNeighbourSearch(particleType=\"RotSphere\", ...))")
            if any(g.tag == prms.tag for g in self._bond_groups):
                refuse(f"LsmMpi.createInteractionGroup({kind}): a second group on bond tag {prms.tag}",
                       "one bond group per tag")
            self._name(prms)
            self._bond_groups.append(prms)
        elif isinstance(prms, (P.NRotElasticWallPrms, P.NRotBondedWallPrms)):
            if isinstance(prms, P.NRotBondedWallPrms) and prms.tagMask != -1:
                refuse(f"LsmMpi.createInteractionGroup(NRotBondedWallPrms(tagMask={prms.tagMask}))",
                       "Basalt's bonded wall ties the particles whose tag equals particleTag (tagMask=-1, "
                       "ESyS's default)")
            if prms.wallName not in self._walls:
                raise ValueError(f"LsmMpi.createInteractionGroup({kind}): no wall named {prms.wallName!r}")
            if prms.wallName in self._wall_k:
                refuse(f"LsmMpi.createInteractionGroup({kind}) on wall {prms.wallName!r} twice",
                       "a Basalt wall has one interaction")
            self._name(prms)
            self._wall_k[prms.wallName] = prms
        elif isinstance(prms, P.NRotElasticTriMeshPrms):
            if prms.meshName not in self._meshes:
                raise ValueError(f"LsmMpi.createInteractionGroup({kind}): no mesh named {prms.meshName!r} "
                                 "(readMesh)")
            if prms.meshName in self._mesh_k:
                refuse(f"LsmMpi.createInteractionGroup({kind}) on mesh {prms.meshName!r} twice",
                       "a Basalt mesh wall has one interaction")
            self._name(prms)
            self._mesh_k[prms.meshName] = prms
        elif isinstance(prms, (P.GravityPrms, P.LinDampingPrms, P.RotDampingPrms)):
            if isinstance(prms, P.RotDampingPrms) and not self._rotational:
                raise ValueError(f"LsmMpi.createInteractionGroup({kind}): rotational damping acts on RotSpheres "
                                 "(initNeighbourSearch(particleType=\"RotSphere\", ...))")
            if any(type(b) is type(prms) for b in self._body):
                refuse(f"LsmMpi.createInteractionGroup: a second {kind}", "one group of each body force")
            self._name(prms)
            self._body.append(prms)
        else:
            refuse(f"LsmMpi.createInteractionGroup({kind})", "the front end maps NRotElasticPrms, RotFrictionPrms, "
                   "FrictionPrms, NRotFrictionPrms, NRotBondPrms, RotBondPrms, BrittleBeamPrms, NRotElasticWallPrms, "
                   "NRotBondedWallPrms, NRotElasticTriMeshPrms, "
                   "GravityPrms, LinDampingPrms and RotDampingPrms so far")

    def createExclusion(self, interactionName1, interactionName2):
        """No force of one group on the pairs the other (a bond group) joins: ESyS's exclusion of a contact group
        from bonded pairs. Basalt's contact models never act on bonded pairs, so a contact group must be excluded
        from every bond group (checked when the run starts); a bond that breaks leaves its pair to the contact
        group from the next step, as in ESyS (docs/reference-runs.md)."""
        self._setup("createExclusion")
        names = {g.name: g for g in (*self._pair, *self._bond_groups)}
        for n in (interactionName1, interactionName2):
            if str(n) not in names:
                others = self._group_names - set(names)
                raise ValueError(f"LsmMpi.createExclusion: no contact or bond group named {str(n)!r}"
                                 + (f" (exclusions between {', '.join(sorted(others))} are not mapped)"
                                    if str(n) in others else ""))
        a, b = names[str(interactionName1)], names[str(interactionName2)]
        bond, pair = (a, b) if a in self._bond_groups else (b, a)
        if bond not in self._bond_groups or pair not in self._pair:
            refuse(f"LsmMpi.createExclusion({interactionName1!r}, {interactionName2!r})",
                   "exclusions between a bond group and a contact group (Basalt's contacts skip bonded pairs)")
        self._exclusions.add((bond.name, pair.name))

    def createWall(self, name, posn, normal):
        self._setup("createWall")
        if name in self._walls or name in self._meshes:
            raise ValueError(f"LsmMpi.createWall: a wall or mesh named {name!r} exists")
        n = Vec3(normal)
        if n.norm() == 0.0:
            raise ValueError(f"LsmMpi.createWall({name!r}): the normal has zero length")
        self._walls[str(name)] = (Vec3(posn), n)

    def readMesh(self, fileName, meshName, *tag, **kwargs):
        """An ESyS .msh triangle mesh (docs/esys.md, "Mesh walls"), read now (relative to the working folder, as
        ESyS reads it); it becomes a Basalt mesh wall (written as OFF beside the run's scene) acting through the
        NRotElasticTriMeshPrms group that names it (none: no force, as in ESyS)."""
        from .mesh import read_msh

        self._setup("readMesh")
        if tag or kwargs:
            refuse(f"LsmMpi.readMesh({fileName!r}, {meshName!r}, tag)",
                   "the front end reads a mesh without a tag (the tag names it for ESyS's mesh savers, which "
                   "Basalt's front end does not write); Basalt's wall_force field saves a mesh wall's force")
        name = str(meshName)
        if name in self._meshes or name in self._walls:
            raise ValueError(f"LsmMpi.readMesh: a wall or mesh named {name!r} exists")
        self._meshes[name] = read_msh(str(fileName))

    def moveWallBy(self, wallName, d):
        """Moves the wall by d now, as ESyS does (a Runnable's move before a step is in that step's forces): the
        run's wall is shifted and the forces of the coming step recomputed (basalt Wall.move_by)."""
        name = str(wallName)
        if name not in self._walls:
            raise ValueError(f"LsmMpi.moveWallBy: no wall named {name!r}")
        d = Vec3(d)
        if not any(d.toList()):  # no move (WallLoader's first steps): the forces stay as the step computed them
            return              # (a recomputation would lose the last pull of the bonds they found broken)
        if self._sim is None:
            posn, normal = self._walls[name]
            self._walls[name] = (posn + d, normal)
            self._moved_before.add(name)
        else:
            self._sim.walls[name].move_by(d.toList())

    def createCheckPointer(self, prms):
        self._setup("createCheckPointer")
        self._checkpointers.append(CheckPointer(prms, self))

    def createFieldSaver(self, prms):
        self._setup("createFieldSaver")
        self._savers.append(FieldSaver(prms, self))

    def addPreTimeStepRunnable(self, runnable):
        self._pre.append(runnable)

    def addPostTimeStepRunnable(self, runnable):
        self._post.append(runnable)

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        refuse(f"LsmMpi.{name}", _HINTS.get(name, "not provided by the front end yet"))

    # -- running --------------------------------------------------------------------------------------------
    def run(self):
        """Runs the remaining steps up to setNumTimeSteps."""
        self._advance(self._num_steps)

    def runTimeStep(self):
        self._advance(self._t + 1)

    def exit(self):
        if self._sim is not None:
            self._sim.close()
            self._sim = None
        self._cleanup()

    def _cleanup(self):
        if self._dir is not None:
            shutil.rmtree(self._dir, ignore_errors=True)
            self._dir = None

    def _start(self):
        from .scene import build

        if self._dt is None:
            raise ValueError("LsmMpi.run: no time step (setTimeStepSize)")
        if self._domain_lo is None:
            raise ValueError("LsmMpi.run: no spatial domain (setSpatialDomain)")
        if not self._particles:
            raise ValueError("LsmMpi.run: no particles (createParticle)")
        self._check_bonded_walls()
        self._check_meshes([p.getId() for p in self._particles], [p.getPosn().toList() for p in self._particles],
                           [p.getRadius() for p in self._particles])
        self._dir = tempfile.mkdtemp(prefix="basalt-esys-")
        atexit.register(self._cleanup)
        self._sim, self._ids, self._init = build(self, self._dir)

    def _bonded_walls(self):
        from . import prms as P

        return {w: g for w, g in self._wall_k.items() if isinstance(g, P.NRotBondedWallPrms)}

    def _check_bonded_walls(self):
        """ESyS ties a tagged particle to the wall only while its centre is within the neighbour table's cell
        (gridSpacing) of the plane, at each neighbour-list update (ntable's getParticlesAtPlane), with the wall's
        displacement counted from its creation; Basalt ties every particle of the tag for the whole run, its
        rest state the start. Refused where the two differ from the start."""
        for w, g in self._bonded_walls().items():
            if w in self._moved_before:
                refuse(f"LsmMpi.moveWallBy({w!r}) before the run, on a wall with NRotBondedWallPrms {g.name!r}",
                       "ESyS counts that move in the bonds' stretch (the wall's displacement from its creation), "
                       "Basalt's bonded wall rests where the run starts: create the wall where it starts, or move "
                       "it from a Runnable")
            posn, normal = self._walls[w]
            n = normal * (1.0 / normal.norm())
            for p in self._particles:
                if p.getTag() == g.particleTag and abs((p.getPosn() - posn).dot(n)) >= self._grid:
                    refuse(f"LsmMpi.createInteractionGroup(NRotBondedWallPrms({g.name!r})): particle {p.getId()} "
                           f"of tag {g.particleTag} is {abs((p.getPosn() - posn).dot(n)):.6g} from wall {w!r}, "
                           f"not within gridSpacing {self._grid:g}",
                           "ESyS leaves such a particle free, Basalt's bonded wall (bond_tags) ties every particle "
                           "of the tag: tag only the particles near the wall")

    def _check_meshes(self, ids, centres, radii):
        """ESyS 2.3.5's mesh triangles push along their normal only, with k (r - d) for any signed distance d < r of
        a centre whose projection is inside (so one behind a face is pushed through it), and its edges and
        corners from either side; Basalt's one-sided mesh wall leaves a centre behind the surface alone. Refused
        where that happens (a centre behind a face within gridSpacing, or behind it and touching its rim)."""
        from .mesh import pushed_twice, touching_from_behind

        for name, (vertices, triangles) in self._meshes.items():
            if name not in self._mesh_k or not len(ids):
                continue
            hit = touching_from_behind(vertices, triangles, centres, radii, self._grid)
            if hit is not None:
                m, k, d = hit
                refuse(f"LsmMpi: particle {int(ids[m])} behind triangle {k} of mesh {name!r} (distance {d:.6g} "
                       f"along ESyS's normal) at step {self._t}",
                       "ESyS 2.3.5's mesh faces push along their normal only (a centre behind a face is pushed "
                       "through it) and its edges and corners from both sides, Basalt's one-sided mesh wall leaves "
                       "a centre behind the mesh alone: keep the particles on the side the triangles' normals "
                       "(p2 - p0) x (p1 - p0) point to")
            twice = pushed_twice(vertices, triangles, centres, radii)
            if twice is not None:
                m, k, l = twice
                refuse(f"LsmMpi: particle {int(ids[m])} touches mesh {name!r} exactly over the shared edge or corner "
                       f"of its coplanar triangles {k} and {l} at step {self._t}",
                       "ESyS 2.3.5 counts such a centre inside both triangles and pushes it once per triangle, "
                       "Basalt's mesh wall once: move the particle off the edge (or the mesh's vertices off the "
                       "particles' lines)")

    def _check_bonds_held(self):
        """A tied particle now a gridSpacing or more from its wall's plane: ESyS drops its bond at the next
        neighbour-list update, Basalt keeps it (refused here rather than run on with different physics)."""
        import numpy as np

        walls = self._bonded_walls()
        if not walls and not self._mesh_k:
            return
        ids, tag, x, y, z, rad = self._columns("tag", "x", "y", "z", "radius")
        self._check_meshes(ids, np.column_stack([x, y, z]), rad)
        for w, g in walls.items():
            n = np.asarray(self._walls[w][1].toList())
            n = n / np.linalg.norm(n)
            d = np.abs((np.column_stack([x, y, z]) - np.asarray(self._sim.walls[w].position)) @ n)
            far = (tag.astype(np.int64) == g.particleTag) & (d >= self._grid)
            if far.any():
                k = int(np.argmax(np.where(far, d, -1.0)))
                refuse(f"LsmMpi.run: particle {int(ids[k])} tied to wall {w!r} by NRotBondedWallPrms {g.name!r} is "
                       f"{d[k]:.6g} from it at step {self._t}, not within gridSpacing {self._grid:g}",
                       "ESyS drops such a bond at its next neighbour-list update, Basalt's bonded wall keeps every "
                       "bond for the whole run")

    def _advance(self, target):
        if self._sim is None:
            self._start()
        import numpy as np

        # ESyS's neighbour-list rule (the checkpoints' 'position at the last rebuild') and its spatial domain,
        # checked after every step in C++ (python/src/esys_watch.hpp): a run goes in chunks between the steps
        # Python must see (savers, Runnables), and stops early at a step whose positions make ESyS rebuild while a
        # particle is outside the domain (the rebuild removes it)
        core = self._sim._core
        if not self._watching:
            lo, hi = self._grid_domain()
            core.esys_watch((0.5 * self._verlet) ** 2, lo, hi)
            self._watching = True
        # the forces a step used (checkpoints, force savers): kept for the step into a save
        track = bool(self._checkpointers) or any(s.prms.fieldName.lower() == "force" for s in self._savers)
        epot = self._bond_energy_saved()
        self._save_due()
        while self._t < target:
            if self._pre or self._post:
                n = 1
            else:
                n = min([target] + [s for s in self._next_saves() if s is not None]) - self._t
                if (track or epot) and n > 1:
                    n -= 1  # the step into the save goes alone
            if epot and n == 1:  # before the Runnables (a moveWallBy recomputes the forces)
                self._prev_bond_energy = self._bond_energy_now()
            if self._pre:
                self._clock = self._t + 1
                for r in self._pre:
                    r.run()
            if track and n == 1:
                ids, fx, fy, fz = self._columns("fx", "fy", "fz")
                self._prev_force = (ids, np.column_stack([fx, fy, fz]))
            if n == 1:  # the walls' push on the particles (+ 0.0: no "-0" where nothing touches, as ESyS prints)
                self._prev_wall_force = {w: 0.0 - np.asarray(self._sim.walls[w].force) for w in self._walls}
            else:  # a chunk: savers and getWallForce fall back to the current forces
                self._prev_wall_force = {}
            self._t += self._sim.run(n)  # (fewer when a rebuild is due with a particle outside the domain)
            self._clock = self._t
            self._save_due()
            for r in self._post:
                r.run()
            if core.esys_watch_rebuild_due():  # ESyS's rebuild as the next step begins removes them
                self._leave_domain()
        self._check_bonds_held()  # and the meshes

    def _bond_energy_saved(self):
        return any(s.prms.kind == "InteractionScalarFieldSaverPrms" and s.prms.fieldName == "potential_energy"
                   for s in self._savers)

    def _bond_energy_now(self):
        """Collective: the bonds' potential energy of this step's force computation, ESyS's definition (rot_bond's
        energy: Fn^2/2kn + Fs^2/2ks + Mt^2/2kt + Mb^2/2kb of the loads it computed, a bond that broke in it
        included), from the scene's bond_potential_energy saver (scene.py); before the first step, the forces of
        the start recomputed (the same positions). ESyS's saver at step t + 1 writes it: ESyS computes the forces
        from the positions after step t at the start of step t + 1, Basalt at the end of step t (docs/esys.md)."""
        v = self._sim.saved_field("bond_potential_energy")
        return self._sim.energies()["bond_potential_energy"] if v is None else v

    def _next_saves(self):
        return [s.next_after(self._t) for s in (*self._savers, *self._checkpointers)]

    def _save_due(self):
        if self._saved >= self._t:
            return
        self._saved = self._t
        due = [s for s in (*self._savers, *self._checkpointers) if s.due(self._t)]
        if due:
            state = self._state()  # collective: every rank gathers it, rank 0 writes
            if self._root:
                for s in due:
                    s.write(self._t, state)

    # -- state ----------------------------------------------------------------------------------------------
    def _columns(self, *names):
        """Collective: (ids, one array per name) of every rank's particles, in id order, on every rank (this
        rank's arrays when it is the only one)."""
        import numpy as np

        sim = self._sim
        if sim.ranks == 1:
            p = sim.particles
            order = np.argsort(p.id, kind="stable")
            return (np.asarray(p.id)[order].astype(np.int64), *(np.asarray(getattr(p, n))[order] for n in names))
        ids, table = sim.gather(list(names) or ["id"], everywhere=True)  # one exchange for all the arrays
        return (ids, *(table[:, k] for k in range(len(names))))

    def _grid_domain(self):
        """ESyS removes a particle once its centre leaves the spatial domain grown to whole cells of gridSpacing,
        centred (measured: [-8, 8] with gridSpacing 2.5 keeps particles up to |x| = 8.75, with 3.0 up to 9)."""
        lo, hi = [], []
        for a, b in zip(self._domain_lo, self._domain_hi):
            half = math.ceil((b - a) / self._grid - 1e-12) * self._grid / 2
            lo.append((a + b) / 2 - half)
            hi.append((a + b) / 2 + half)
        return lo, hi

    def _leave_domain(self):
        """Deletes the particles outside the (grown) spatial domain, as ESyS does at its neighbour-list rebuilds
        (measured, docs/esys.md: listed up to the step whose positions trigger the rebuild, gone from the next):
        all of them in one rebuild, the references taken again (esys_watch.hpp)."""
        self._sim._core.esys_watch_leave()

    def _state(self):
        import numpy as np

        names = ["tag", "radius", "inv_mass", "x", "y", "z", "vx", "vy", "vz", "fx", "fy", "fz"]
        if self._rotational:
            names += ["wx", "wy", "wz"]
            if self._checkpointers:  # the scene keeps orientations then (scene.py)
                names += ["qw", "qx", "qy", "qz"]
        ids, *cols = self._columns(*names)
        c = dict(zip(names, cols))
        where = np.searchsorted(self._ids, ids)
        state = {
            "id": ids, "tag": c["tag"].astype(np.int64), "radius": c["radius"], "mass": 1.0 / c["inv_mass"],
            "pos": np.column_stack([c["x"], c["y"], c["z"]]), "vel": np.column_stack([c["vx"], c["vy"], c["vz"]]),
            "init": self._init[where],
            "walls": {n: (np.asarray(w.position), np.asarray(w.force)) for n, w in
                      ((n, self._sim.walls[n]) for n in self._walls)},
        }
        if self._prev_force is not None:  # the forces the last step used, by id (a removal may come between)
            prev_ids, prev = self._prev_force
            state["force"] = prev[np.searchsorted(prev_ids, ids)]
        else:
            state["force"] = np.column_stack([c["fx"], c["fy"], c["fz"]])
        state["walls"] = {n: (pos, self._prev_wall_force.get(n, -f)) for n, (pos, f) in state["walls"].items()}
        if self._bond_energy_saved():  # ESyS's bonds hold the loads of its last force computation (0 at first)
            state["bond_energy"] = self._prev_bond_energy if self._t > 0 else 0.0
        if self._t == 0:  # before the first step ESyS holds no forces
            state["force"] = np.zeros_like(state["pos"])
            state["walls"] = {n: (pos, np.zeros(3)) for n, (pos, f) in state["walls"].items()}
        old_ids, old = self._sim._core.esys_watch_reference()
        state["old"] = old if np.array_equal(old_ids, ids) else state["pos"]
        if self._rotational:
            state["angvel"] = np.column_stack([c["wx"], c["wy"], c["wz"]])
            if self._checkpointers:
                state["quat"] = np.column_stack([c["qw"], c["qx"], c["qy"], c["qz"]])
        counts = any(s.prms.kind == "InteractionScalarFieldSaverPrms" for s in self._savers)
        if (self._checkpointers or counts) and self._bond_groups:  # collective: read on every rank, rank 0 writes
            state["broken_bonds"] = {(int(i), int(j)): int(s) for i, j, s in self._sim.broken_bond_pairs().tolist()}
        return state

    def getParticleList(self):
        """The particles now (copies, in id order)."""
        if self._sim is None:
            return [_copy(p) for p in sorted(self._particles, key=lambda q: q.getId())]
        s = self._state()
        kind = RotSphere if self._rotational else NRotSphere
        out = []
        for i in range(len(s["id"])):
            q = kind(int(s["id"][i]), Vec3(*s["init"][i]), float(s["radius"][i]), float(s["mass"][i]))
            q._posn, q._vel, q._tag = Vec3(*s["pos"][i]), Vec3(*s["vel"][i]), int(s["tag"][i])
            q._force = Vec3(*s["force"][i])
            if self._rotational:
                q._angvel = Vec3(*s["angvel"][i])
            out.append(q)
        return out

    def getNumParticles(self):
        return len(self._particles) if self._sim is None else self._sim.total_particles

    def getWallPosition(self, name):
        if self._sim is None:
            return Vec3(self._walls[name][0])
        return Vec3(*self._sim.walls[name].position)

    def getWallForce(self, name):
        """The wall saver's Force: the wall's push on the particles in the last step (0 before the first)."""
        if self._sim is None or self._t == 0:
            return Vec3(0.0, 0.0, 0.0)
        if name in self._prev_wall_force:
            return Vec3(*self._prev_wall_force[name])
        return Vec3(*(0.0 - c for c in self._sim.walls[name].force))


def _copy(p):
    q = type(p).__new__(type(p))
    q.__dict__.update({k: (Vec3(v) if isinstance(v, Vec3) else v) for k, v in p.__dict__.items()})
    return q
