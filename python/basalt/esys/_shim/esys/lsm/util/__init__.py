"""esys.lsm.util on Basalt: Vec3, BoundingBox."""
from basalt.esys.api import module_getattr
from basalt.esys.vec3 import BoundingBox, Vec3

__all__ = ["Vec3", "BoundingBox"]
__getattr__ = module_getattr("esys.lsm.util")
