"""gengeo (GenGeo, ESyS-Particle's geometry generator) inside `python3 -m basalt.esys` only: refused.

Basalt does not reproduce GenGeo's packing (InsertGenerator3D's fit of each new sphere to its four nearest
neighbours by a simplex search) to the digit yet (docs/esys.md, "GenGeo"), and a module that packed other
spheres under GenGeo's names would change a script's geometry silently. Every name, and `from gengeo import *`,
raises NotSupportedError naming basalt.pack. Outside the runner this folder is not on sys.path: `import gengeo`
finds a real GenGeo, or nothing."""
from basalt.esys.errors import refuse

_OFFER = ("GenGeo's packing is not reproduced by Basalt yet; Basalt packs spheres with basalt.pack (box, "
          "cylinder, sphere, mesh; lattice=True for a regular one; bonds between touching spheres), or run the "
          "GenGeo script with GenGeo itself and read its .geo with readGeometry")


def __getattr__(name):
    if name.startswith("__") and name != "__all__":
        raise AttributeError(name)
    refuse("gengeo (from gengeo import *)" if name == "__all__" else f"gengeo.{name}", _OFFER)
