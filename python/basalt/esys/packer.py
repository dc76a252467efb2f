"""esys.lsm.geometry.RandomBoxPacker as ESyS-Particle 2.3.5 packs a box (3-D, no periodic axis): the same spheres,
ids and order, bit for bit (docs/esys.md; tests/python/test_esys_front.py compares with packings ESyS wrote).

The packing itself is compiled (python/src/esys_packer.cpp, which says how ESyS packs): every floating-point
operation in the order ESyS makes it, with one random stream for the whole process (MT19937 seeded 5489, as
ESyS's static generator), so that a second packer in the same script continues the stream, as in ESyS."""

from .._core_loader import core
from .blocks import SimpleSphere, SphereCollection
from .errors import refuse
from .vec3 import Vec3

_RNG = None  # the process's one stream, as ESyS's static generator


def _stream():
    global _RNG
    if _RNG is None:
        _RNG = core().EsysStream()
    return _RNG


class RandomBoxPacker:
    """RandomBoxPacker(minRadius, maxRadius, cubicPackRadius, maxInsertFails, bBox, circDimList=[False]*3,
    tolerance=0.001): ESyS's random packing of a 3-D box without periodic axes, reproduced (module docstring)."""

    def __init__(self, minRadius, maxRadius, cubicPackRadius, maxInsertFails, bBox,
                 circDimList=(False, False, False), tolerance=0.001):
        circ = [bool(c) for c in circDimList]
        if any(circ):
            refuse(f"esys.lsm.geometry.RandomBoxPacker(circDimList={list(circ)})",
                   "Basalt reproduces ESyS's packing of a box without periodic axes; basalt.pack.box packs a "
                   "periodic box, with other spheres")
        self._lo = tuple(float(v) for v in bBox.getMinPt())
        self._hi = tuple(float(v) for v in bBox.getMaxPt())
        if self._hi[2] - self._lo[2] <= 0:
            refuse("esys.lsm.geometry.RandomBoxPacker with a 2-D box (zero size along z)",
                   "Basalt reproduces ESyS's packing of a 3-D box; basalt.pack packs 3-D boxes")
        self._rmin, self._rmax = float(minRadius), float(maxRadius)
        if not self._rmin > 0.0 or not self._rmax >= self._rmin:
            raise ValueError(f"esys.lsm.geometry.RandomBoxPacker(minRadius={minRadius}, maxRadius={maxRadius}): "
                             "give 0 < minRadius <= maxRadius")
        self._cubic = float(cubicPackRadius)
        self._max_fails = int(maxInsertFails)
        self._tol = float(tolerance)
        self._spheres = None
        self._packer = core().EsysBoxPacker(self._lo, self._hi, self._rmin, self._rmax, self._cubic,
                                            self._max_fails, self._tol)

    # -- ESyS's Python methods
    def generate(self):
        """Packs the box; called again, packs again around the spheres already there (as ESyS: the grid, then
        random insertion), the ids going on."""
        x, y, z, r = self._packer.generate(_stream())
        spheres = self._spheres or []  # the spheres of an earlier generate() stay the same objects
        for i in range(len(spheres), len(x)):
            spheres.append(SimpleSphere(i, Vec3(x[i], y[i], z[i]), r[i]))
        self._spheres = spheres

    def getSimpleSphereCollection(self):
        return SphereCollection(self._spheres or [])

    def getSimpleSphereIterator(self):
        return iter(list(self._spheres or []))

    def getNumSpheres(self):
        return len(self._spheres or [])
