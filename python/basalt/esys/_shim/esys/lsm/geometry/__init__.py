"""esys.lsm.geometry on Basalt: its generators are refused (NotSupportedError names basalt.pack)."""
from basalt.esys.api import module_getattr
from basalt.esys.refused import GEOMETRY, stubs

globals().update(stubs("esys.lsm.geometry", GEOMETRY))
__all__ = sorted(GEOMETRY)
__getattr__ = module_getattr("esys.lsm.geometry")
