"""esys.lsm on Basalt (basalt.esys.api): LsmMpi, particles, parameter classes; refused names raise."""
from basalt.esys.api import *  # noqa: F401,F403
from basalt.esys.api import __all__, module_getattr  # noqa: F401

__getattr__ = module_getattr("esys.lsm")
