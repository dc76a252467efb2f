"""The Basalt scene of an LsmMpi's set-up: ESyS's calls mapped onto Basalt's models (docs/esys.md).

    NRotElasticPrms(scaling=False)  -> linear_elastic, K = normalK
    NRotElasticPrms(scaling=True)   -> k = normalK (r1 + r2)/4 per pair (ESyS's 3-D scaling): Basalt's
                                       rot_friction with scaling = true, Ks = 0 and mu = 0 (no shear force,
                                       no moment: the same normal force), particles.rotation on
    NRotElasticWallPrms             -> the wall's K with stiffness = "esys_pi_r" (k = pi r K)
    NRotBondedWallPrms              -> interaction = "bonded", bond_tags = [particleTag], the same K and stiffness
    readMesh + NRotElasticTriMeshPrms -> a [[mesh_walls]] (the .msh written as OFF), elastic, k = r K, one-sided
    a wall without a group          -> K = 0 (ESyS: no force on it)
    RotFrictionPrms, FrictionPrms   -> rot_friction, convention "esys" (FrictionPrms: K = pi E, Ks = pi E/(2(1 + nu)),
                                       scaling); NRotFrictionPrms -> friction, convention "esys", mu = dynamicMu
    GravityPrms, LinDampingPrms,    -> [[body_forces]] gravity, linear_damping, rotational_damping (ESyS's
    RotDampingPrms                     iterative rule)
    InteractionScalarFieldSaverPrms -> [[output.fields]] bond_potential_energy every step (rot_bond's energy is
    (potential_energy)                 ESyS's, read by LsmMpi through saved_field)
    always                          -> symplectic Euler (ESyS's integrator), masses as given, skin = verletDist,
                                       no energy check and no start-up overlap/dt refusal (ESyS has neither)
"""

import os

from . import prms as P
from .errors import refuse
from .mesh import write_off


def scene_dict(lsm, geometry_file, output_dir, mesh_files=None):
    interactions, rotation = [], lsm._rotational
    for g in lsm._pair:
        if isinstance(g, P.RotFrictionPrms):  # also FrictionPrms (K = pi E, Ks = pi E / (2 (1 + nu)))
            interactions.append({"type": "rot_friction", "K": g.normalK, "Ks": g.shearK, "mu": g.staticMu,
                                 "mu_dynamic": g.dynamicMu, "convention": "esys", "scaling": g.scaling})
            rotation = True
        elif isinstance(g, P.NRotFrictionPrms):
            interactions.append({"type": "friction", "K": g.normalK, "Ks": g.shearK, "mu": g.dynamicMu,
                                 "mu_dynamic": g.dynamicMu, "convention": "esys", "scaling": g.scaling})
        elif g.scaling:
            interactions.append({"type": "rot_friction", "K": g.normalK, "Ks": 0.0, "mu": 0.0, "mu_dynamic": 0.0,
                                 "convention": "esys", "scaling": True})
            rotation = True
        else:
            interactions.append({"type": "linear_elastic", "K": g.normalK})
    split = bond_split(lsm)
    for g in lsm._bond_groups:
        if not isinstance(g, P.NRotBondPrms):  # RotBondPrms, BrittleBeamPrms
            interactions.append(dict(g.model(), bond_tag=g.tag))
            rotation = True
            continue
        bond = {"type": "linear_bond", "K": g.normalK, "rest_length": "sum_of_radii",
                "break_strain": g.breakDistance, "convention": "esys", "bond_tag": g.tag}
        sizes = split.get(g.tag)
        if not sizes:
            interactions.append(bond)
        for r0, geo_tag in sorted((sizes or {}).items()):
            # ESyS: k = normalK (r0/2)^2 / r0 per bond (BondedInteraction.cpp); one Basalt group per r0
            eff = 0.5 * r0
            interactions.append(dict(bond, K=g.normalK * (eff * eff) / (2.0 * eff), bond_tag=geo_tag))
    _check_exclusions(lsm)
    walls = []
    for name, (posn, normal) in lsm._walls.items():
        k = lsm._wall_k.get(name)
        wall = {"name": name, "point": posn.toList(), "normal": normal.toList(), "K": k.normalK if k else 0.0,
                "stiffness": "esys_pi_r"}
        if isinstance(k, P.NRotBondedWallPrms):  # k = pi r K for the bond and the elastic part, ESyS's literals
            wall.update(interaction="bonded", bond_tags=[k.particleTag])
        walls.append(wall)
    meshes = []
    for name in lsm._meshes:
        k = lsm._mesh_k.get(name)
        if k is None:  # ESyS: a mesh no interaction group names pushes nothing
            continue
        # ESyS 2.3.5 (Debian, measured): k = r K (no pi), faces one-sided along ESyS's normal (the OFF is wound for
        # it); Basalt's esys_pi_r gives k = 3.141592654 r K', so K' = K / 3.141592654
        meshes.append({"name": name, "file": mesh_files[name], "interaction": "elastic",
                       "K": k.normalK / ESYS_WALL_PI, "stiffness": "esys_pi_r", "sides": "one"})
    body = []
    for b in lsm._body:
        if isinstance(b, P.GravityPrms):
            body.append({"type": "gravity", "acceleration": b.acceleration.toList()})
        elif isinstance(b, P.RotDampingPrms):
            body.append({"type": "rotational_damping", "viscosity": b.viscosity, "iterations": b.maxIterations})
        else:
            body.append({"type": "linear_damping", "viscosity": b.viscosity, "iterations": b.maxIterations})
    scene = {
        "geometry": {"file": geometry_file},
        # RotSphere checkpoints hold the orientations (kept without changing any other bit, docs/scenes.md)
        "particles": dict({"rotation": rotation}, **({"orientation": True} if lsm._rotational and
                                                      lsm._checkpointers else {})),
        "run": {"dt": lsm._dt, "skin": lsm._verlet, "integrator": "symplectic_euler", "force_dt": True,
                "force_overlap": True, "energy_check_every": 0},
        "output": {"directory": output_dir},
    }
    if any(sv.prms.kind == "InteractionScalarFieldSaverPrms" and sv.prms.fieldName == "potential_energy"
           for sv in lsm._savers):  # the bonds' energy of each step's forces, read by LsmMpi (saved_field)
        scene["output"]["fields"] = [{"type": "bond_potential_energy", "every": 1}]
    for key, value in (("interactions", interactions), ("walls", walls), ("mesh_walls", meshes),
                       ("body_forces", body)):
        if value:
            scene[key] = value
    return scene


MAX_BOND_SIZES = 64
ESYS_WALL_PI = 3.141592654  # the literal of Basalt's esys_pi_r elastic wall (models/elastic_wall.hpp)


def bond_split(lsm):
    """{ESyS bond tag: {r1 + r2: the geometry's bond tag}} for the scaled NRotBondPrms groups: ESyS gives each bond
    its own k = normalK (r0/2)^2/r0, Basalt's linear_bond one K per group, so the bonds of each size r0 = r1 + r2
    get a group of their own (a tag of the written geometry; ESyS's tags stay in the script's view). One size keeps
    the ESyS tag; at most MAX_BOND_SIZES sizes per group (a random packing's bonds are each of their own size)."""
    radius = {p.getId(): p.getRadius() for p in lsm._particles}
    used = {t for _, _, t in lsm._bonds} | {g.tag for g in lsm._bond_groups}
    fresh = max(used, default=0) + 1
    split = {}
    for g in lsm._bond_groups:
        if not (isinstance(g, P.NRotBondPrms) and g.scaling):
            continue
        sizes = sorted({radius[i] + radius[j] for i, j, t in lsm._bonds if t == g.tag})
        if len(sizes) > MAX_BOND_SIZES:
            refuse(f"LsmMpi: NRotBondPrms({g.name!r}, scaling=True) on bonds of {len(sizes)} different r1 + r2",
                   f"the front end gives each bond size its own Basalt linear_bond group, up to {MAX_BOND_SIZES}; "
                   "for a random packing use Basalt's linear_bond (one K) in a basalt.Simulation scene")
        if len(sizes) == 1:
            split[g.tag] = {sizes[0]: g.tag}
        elif sizes:
            split[g.tag] = {r0: fresh + k for k, r0 in enumerate(sizes)}
            fresh += len(sizes)
    return split


def _check_exclusions(lsm):
    """Basalt's contact models never act on a bonded pair (until its bond breaks); ESyS's contact group does unless
    createExclusion excludes it from the bond group. So with a contact group every bond must belong to a group
    excluded from it."""
    if not lsm._pair or not (lsm._bonds or lsm._bond_groups):
        return
    pair = lsm._pair[0]
    groups = {g.tag: g for g in lsm._bond_groups}
    for tag in sorted({t for _, _, t in lsm._bonds} | set(groups)):
        g = groups.get(tag)
        if g is None:
            refuse(f"LsmMpi: connections of tag {tag} (no bond group) with the contact group {pair.name!r}",
                   "ESyS's contact group acts on those pairs, Basalt's contacts skip every bonded pair: give the "
                   "tag a bond group excluded from the contact group (createExclusion), or leave those connections "
                   "out")
        if (g.name, pair.name) not in lsm._exclusions:
            refuse(f"LsmMpi: the contact group {pair.name!r} together with the bond group {g.name!r} without "
                   f"createExclusion({g.name!r}, {pair.name!r})",
                   "ESyS's contact group also pushes bonded pairs unless excluded; Basalt's contacts skip bonded "
                   "pairs: add the exclusion (as ESyS's rot_compress does)")


def build(lsm, workdir):
    """Writes the particles as a Basalt geometry in workdir and starts the run: (Simulation, ids sorted,
    initial positions in that order)."""
    import numpy as np

    from ..geometry import Geometry
    from ..simulation import Simulation

    ps = sorted(lsm._particles, key=lambda p: p.getId())
    ids = np.array([p.getId() for p in ps], dtype=np.int64)
    if len(np.unique(ids)) != len(ids):
        raise ValueError("LsmMpi: two particles have the same id")
    pos = np.array([p.getPosn().toList() for p in ps], dtype=float)
    bonds = sorted(set(lsm._bonds))
    known = set(ids.tolist())
    for i, j, _ in bonds:
        if i not in known or j not in known:
            raise ValueError(f"LsmMpi.createConnections: a bond between {i} and {j}, not both particles")
    extra = {}
    if bonds:
        split, radius = bond_split(lsm), {p.getId(): p.getRadius() for p in ps}
        extra = {"bonds": np.array([(i, j) for i, j, _ in bonds], dtype=np.int64),
                 "bond_tag": np.array([split[t][radius[i] + radius[j]] if t in split else t for i, j, t in bonds],
                                      dtype=np.int32)}
    geo = Geometry(pos, np.array([p.getRadius() for p in ps]), id=ids, **extra,
                   tag=np.array([p.getTag() for p in ps], dtype=np.int32),
                   mass=np.array([p.getMass() for p in ps]), box_min=lsm._domain_lo, box_max=lsm._domain_hi)
    path = os.path.join(workdir, "particles.h5")
    geo.write(path)
    mesh_files = {}
    for k, (name, (vertices, triangles)) in enumerate(lsm._meshes.items()):
        mesh_files[name] = os.path.join(workdir, f"mesh{k}.off")
        write_off(mesh_files[name], vertices, triangles)
    sim = Simulation(scene_dict(lsm, path, os.path.join(workdir, "out"), mesh_files))
    vel = {p.getId(): p.getVelocity().toList() for p in ps}
    angvel = {p.getId(): p.getAngularVelocity().toList() for p in ps if hasattr(p, "getAngularVelocity")}
    _set_initial_velocities(sim, vel, angvel)
    return sim, ids, pos


def _set_initial_velocities(sim, vel, angvel):
    """The created particles' velocities ({id: [3 numbers]}), written into the run's arrays before the first
    step; then the forces are recomputed (the damping reads velocities) and the contacts' shear springs take
    that computation's increment dt u(0), as ESyS's first step does (measured with slide.py)."""
    import numpy as np

    part = sim.particles
    ids = np.asarray(part.id)
    written = False
    for table, names in ((vel, ("vx", "vy", "vz")), (angvel, ("wx", "wy", "wz"))):
        if not table or not any(any(v) for v in table.values()):
            continue
        values = np.array([table[int(i)] for i in ids], dtype=float).reshape(len(ids), 3)
        for k, name in enumerate(names):
            getattr(part, name)[:] = values[:, k]
        written = True
    # (only then: a recomputation has no bond the start's forces broke, whose last pull ESyS's step 1 applies)
    if written:
        sim._core.state_changed(advance_history=True)
