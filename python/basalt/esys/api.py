"""The names of esys.lsm that Basalt's ESyS front end provides (the shim's esys.lsm re-exports them), and the
ones it refuses (a call raises NotSupportedError saying what Basalt offers)."""

# re-exported through __all__ (SUPPORTED)
from .errors import NotSupportedError, refuse
from .lsmmpi import LsmMpi  # noqa: F401
from .particles import NRotSphere, RotSphere  # noqa: F401
from .prms import (BrittleBeamPrms, CheckPointPrms, FrictionPrms, GravityPrms, LinDampingPrms,  # noqa: F401
                   NRotBondPrms, NRotBondedWallPrms, NRotElasticPrms, NRotElasticTriMeshPrms,
                   NRotElasticWallPrms, NRotFrictionPrms, RotBondPrms,
                   RotDampingPrms, RotFrictionPrms, ParticleScalarFieldSaverPrms, ParticleVectorFieldSaverPrms,
                   Runnable, WallVectorFieldSaverPrms, InteractionScalarFieldSaverPrms)
from .refused import LSM, stubs
from .vec3 import BoundingBox, Vec3  # noqa: F401

globals().update(stubs("esys.lsm", LSM))

SUPPORTED = ["LsmMpi", "NRotSphere", "RotSphere", "NRotElasticPrms", "NRotBondPrms", "RotBondPrms",
             "BrittleBeamPrms", "NRotElasticWallPrms", "NRotBondedWallPrms",
             "NRotElasticTriMeshPrms",
             "RotFrictionPrms", "FrictionPrms", "NRotFrictionPrms", "RotDampingPrms", "GravityPrms",
             "LinDampingPrms", "CheckPointPrms", "ParticleScalarFieldSaverPrms", "ParticleVectorFieldSaverPrms",
             "WallVectorFieldSaverPrms", "InteractionScalarFieldSaverPrms", "Runnable", "Vec3", "BoundingBox"]
REFUSED = sorted(LSM)
__all__ = SUPPORTED + REFUSED + ["NotSupportedError"]


def module_getattr(module):
    """A module __getattr__ refusing every other public name of `module` (e.g. "esys.lsm")."""
    def __getattr__(name):
        if name.startswith("__"):
            raise AttributeError(name)
        refuse(f"{module}.{name}", "not provided by the front end yet")
    return __getattr__


__doc__ += "\n\nNotSupportedError: " + (NotSupportedError.__doc__ or "")
