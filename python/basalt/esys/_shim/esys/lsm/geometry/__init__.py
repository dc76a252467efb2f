"""esys.lsm.geometry on Basalt: CubicBlock, SimpleSphere, ConnectionFinder (as ESyS makes them); its other
generators are refused (NotSupportedError names basalt.pack)."""
from basalt.esys.api import module_getattr
from basalt.esys.blocks import CubicBlock, ConnectionFinder, SimpleSphere
from basalt.esys.refused import GEOMETRY, stubs

globals().update(stubs("esys.lsm.geometry", GEOMETRY))
__all__ = ["CubicBlock", "ConnectionFinder", "SimpleSphere"] + sorted(GEOMETRY)
__getattr__ = module_getattr("esys.lsm.geometry")
