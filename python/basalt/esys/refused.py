"""ESyS-Particle names Basalt's front end knows but does not provide yet: each is a class whose construction
raises NotSupportedError naming the call and what Basalt offers (never a silent no-op)."""

from .errors import refuse

_SCENE = "Basalt has it as a scene model (basalt.Simulation with a scene dict, docs/scenes.md): "

# esys.lsm: parameter classes and savers -> what Basalt offers
LSM = {
    "RotElasticPrms": _SCENE + 'type = "linear_elastic"',
    "HertzianElasticPrms": _SCENE + 'type = "hertz_mindlin"',
    "HertzianViscoElasticPrms": _SCENE + 'type = "hertz_mindlin"',
    "HertzianViscoElasticFrictionPrms": _SCENE + 'type = "hertz_mindlin"',
    "HertzMindlinPrms": _SCENE + 'type = "hertz_mindlin"',
    "HertzMindlinViscoPrms": _SCENE + 'type = "hertz_mindlin"',
    "LinearDashpotPrms": "Basalt has no dashpot pair model; damping is the linear_damping body force",
    "RotBondedWallPrms": _SCENE + '[[walls]] interaction = "bonded"',
    "ViscWallPrms": "Basalt's walls are elastic, frictional, Hertz-Mindlin or bonded (docs/scenes.md)",
    "InteractionVectorFieldSaverPrms": "Basalt's checkpoints hold the bonds and contacts (basalt.read_checkpoint)",
    "ParticleTensorFieldSaverPrms": "Basalt's [[output.fields]] stress savers (docs/scenes.md)",
    "WallScalarFieldSaverPrms": "WallVectorFieldSaverPrms (Position, Force) or Basalt's wall_force field",
    "MeshReader": "Basalt's mesh walls ([[mesh_walls]], docs/mesh-walls.md)",
    "TriMeshPrms": "Basalt's mesh walls ([[mesh_walls]], docs/mesh-walls.md)",
    "NRotBondedTriMeshPrms": "Basalt's mesh walls ([[mesh_walls]], docs/mesh-walls.md)",
}

_PACK = "Basalt packs spheres with basalt.pack (box, cylinder, sphere, mesh; lattice=True for a regular one)"
# esys.lsm.geometry: generators
GEOMETRY = {name: _PACK for name in (
    "SimpleBlock", "RandomSpherePacker", "SimpleSphereCollection",
    "ParticleCollection", "GrainCollection")}


def stub(module, name, offer):
    def __init__(self, *args, **kwargs):
        refuse(f"{module}.{name}", offer)
    return type(name, (), {"__init__": __init__, "__doc__": f"Refused by Basalt's ESyS front end: {offer}."})


def stubs(module, table):
    return {name: stub(module, name, offer) for name, offer in table.items()}
