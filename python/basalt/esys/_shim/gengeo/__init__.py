"""gengeo (GenGeo, ESyS-Particle's geometry generator) inside `python3 -m basalt.esys` only: GenGeo's box packing
rebuilt (basalt.esys.gengeo, docs/esys.md "GenGeo"): Vector3, Plane, Sphere, BoxWithPlanes3D, MNTable3D and
InsertGenerator3D give the spheres, ids, tags, bonds and .geo file of Debian's GenGeo 1.4. Its other volumes,
packers and table calls are refused (NotSupportedError naming basalt.pack), never packed differently. Outside the
runner this folder is not on sys.path: `import gengeo` finds a real GenGeo, or nothing."""
from basalt.esys.errors import refuse
from basalt.esys.gengeo import (BoxWithPlanes3D, InsertGenerator3D, MNTable3D, Plane, Sphere,  # noqa: F401
                                Vector3)

__all__ = ["Vector3", "Plane", "Sphere", "BoxWithPlanes3D", "MNTable3D", "InsertGenerator3D"]

_OFFER = ("Basalt reproduces GenGeo's BoxWithPlanes3D packing by InsertGenerator3D only; Basalt packs other "
          "shapes with basalt.pack (box, cylinder, sphere, mesh; lattice=True for a regular one; bonds between "
          "touching spheres), or run the GenGeo script with GenGeo itself and read its .geo with readGeometry")


def __getattr__(name):
    if name.startswith("__"):
        raise AttributeError(name)
    refuse(f"gengeo.{name}", _OFFER)
