"""esys.lsm.vis on Basalt: `povray` (the tutorial's POV-Ray snapshots, drawn with VTK: basalt.esys.vis);
ESyS's `vtk` and `core` packages are refused."""
import importlib

from basalt.esys.errors import refuse

__all__ = ["povray"]


def __getattr__(name):
    if name.startswith("__"):
        raise AttributeError(name)
    if name == "povray":  # `from esys.lsm.vis import povray` asks here before it imports the submodule
        return importlib.import_module(__name__ + ".povray")
    refuse(f"esys.lsm.vis.{name}", "esys.lsm.vis.povray's Scene, Sphere, colours and camera, drawn with VTK "
           "(docs/esys.md, \"POV-Ray snapshots\"); basalt-view renders Basalt's own checkpoints")
