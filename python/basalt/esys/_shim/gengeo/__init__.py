"""gengeo (GenGeo, ESyS-Particle's geometry generator) inside `python3 -m basalt.esys` only: GenGeo's box packing
rebuilt (basalt.esys.gengeo, docs/esys.md "GenGeo"): Vector3, Plane, Sphere, BoxWithPlanes3D, MNTable3D and
InsertGenerator3D give the spheres, ids, tags, bonds and .geo file of Debian's GenGeo 1.4. Its other volumes,
packers and table calls are refused (NotSupportedError naming basalt.pack), never packed differently. Outside the
runner this folder is not on sys.path: `import gengeo` finds a real GenGeo, or nothing."""
from basalt.esys.errors import refuse
from basalt.esys.gengeo import (OFFER, REFUSED, BoxWithPlanes3D, InsertGenerator3D, MNTable3D,  # noqa: F401
                                Plane, Sphere, Vector3)
from basalt.esys.refused import stub

# GenGeo's other names exist, so that `from gengeo import *` brings them, and refuse when used
globals().update({name: stub("gengeo", name, OFFER) for name in REFUSED})
__all__ = ["Vector3", "Plane", "Sphere", "BoxWithPlanes3D", "MNTable3D", "InsertGenerator3D"] + REFUSED
_OFFER = OFFER


def __getattr__(name):
    if name.startswith("__"):
        raise AttributeError(name)
    refuse(f"gengeo.{name}", _OFFER)
