"""esys.lsm.geometry on Basalt: CubicBlock, HexagBlock, RandomBoxPacker, SimpleSphere, ConnectionFinder (as ESyS
makes them), TaggedIdConnection; its other generators are refused (NotSupportedError names basalt.pack)."""
from basalt.esys.api import module_getattr
from basalt.esys.blocks import CubicBlock, ConnectionFinder, HexagBlock, SimpleSphere
from basalt.esys.blocks import Connection as TaggedIdConnection
from basalt.esys.packer import RandomBoxPacker
from basalt.esys.refused import GEOMETRY, stubs

globals().update(stubs("esys.lsm.geometry", GEOMETRY))
__all__ = ["CubicBlock", "HexagBlock", "RandomBoxPacker", "ConnectionFinder", "SimpleSphere", "TaggedIdConnection"] + sorted(GEOMETRY)
__getattr__ = module_getattr("esys.lsm.geometry")
