"""esys.lsm.vis.povray on Basalt (basalt.esys.vis.povray): Scene, Sphere, Colors, RgbColor, Pigment and the
camera, drawn with VTK into the file Scene.render names; the other names are refused."""
from basalt.esys.vis.povray import *  # noqa: F401,F403
from basalt.esys.vis.povray import __all__, module_getattr  # noqa: F401

__getattr__ = module_getattr
