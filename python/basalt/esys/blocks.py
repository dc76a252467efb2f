"""esys.lsm.geometry's CubicBlock, SimpleSphere and ConnectionFinder, as ESyS-Particle 2.3.5 makes them
(Geometry/ClosePackIterator.hpp, CubicBlockIterator.hpp, DistConnections.hpp; checked against ESyS's own
module, docs/esys.md): the same spheres in the same order, bit for bit."""

import math

from .vec3 import Vec3

_SQRT_1_OVER_3 = 1.0 / math.sqrt(3.0)
_SQRT_8_OVER_3 = math.sqrt(8.0 / 3.0)
_SQRT_3 = math.sqrt(3.0)


class SimpleSphere:
    """A sphere of a generated block: id, position, radius, tag 0 and mass r^3 (ESyS's SimpleSphere)."""

    def __init__(self, id=0, posn=(0.0, 0.0, 0.0), radius=1.0, mass=None, tag=0):
        self._id, self._posn, self._radius = int(id), Vec3(posn), float(radius)
        self._mass = self._radius * self._radius * self._radius if mass is None else float(mass)  # ESyS: r*r*r
        self._tag = int(tag)

    def getId(self):
        return self._id

    def setId(self, i):
        self._id = int(i)

    def getTag(self):
        return self._tag

    def setTag(self, t):
        self._tag = int(t)

    def getPosn(self):
        return Vec3(self._posn)

    getPos = getCentre = getCenter = getPosn

    def setPosn(self, p):
        self._posn = Vec3(p)

    setPos = setCentre = setCenter = setPosn

    def getRadius(self):
        return self._radius

    getRad = getRadius

    def setRadius(self, r):
        self._radius = float(r)

    setRad = setRadius

    def getMass(self):
        return self._mass

    def setMass(self, m):
        self._mass = float(m)

    def rotate(self, axis, axisPt):
        self._posn = self._posn.rotate(axis, axisPt)

    def translate(self, translation):
        self._posn = self._posn + Vec3(translation)


def _x_offset(a, b, r):
    """CubicBlockIterator's offset matrix for the first axis: m(0, a % 6, b % 6)."""
    row = (0.0, 0.0, r, 0.0, 0.0, r) if a % 2 == 0 else (r, r, 0.0, r, r, 0.0)
    return row[b % 6]


class SphereCollection:
    """Spheres as ESyS's blocks and SimpleSphereCollection hold them: iterable, len, getNumSpheres, translate,
    rotate (a block fills self._spheres; a packer's collection is handed its list)."""

    def __init__(self, spheres=()):
        self._spheres = list(spheres)

    def __iter__(self):
        return iter(self._spheres)

    def __len__(self):
        return len(self._spheres)

    def getNumSpheres(self):
        return len(self._spheres)

    def rotate(self, axis, axisPt):
        for s in self._spheres:
            s.rotate(axis, axisPt)

    def translate(self, translation):
        for s in self._spheres:
            s.translate(translation)


class _ClosePackBlock(SphereCollection):
    """ESyS's ClosePackIterator: sphere (i, j, k) at offsets(i, j, k) + (2r i, r sqrt(3) j, r sqrt(8/3) k) along the
    axes (x, z, y) of the default orientation, i fastest; ids from 0 in that order."""

    NAME = ""

    def __init__(self, dimCount, radius, orientation=None):
        if orientation is not None:
            from .errors import refuse
            refuse(f"esys.lsm.geometry.{self.NAME}(orientation=...)", "the default orientation is supported")
        counts = [max(int(c), 1) for c in dimCount]
        r = float(radius)
        dim = (0, 2, 1)  # ClosePackIterator's map for the default orientation
        self._spheres = []
        for k in range(counts[2]):
            for j in range(counts[1]):
                for i in range(counts[0]):
                    a, b = self._offsets(i, j, k, r)
                    centre = [0.0, 0.0, 0.0]
                    centre[dim[0]] = a + i * (r * 2.0)
                    centre[dim[1]] = b + j * (r * _SQRT_3)
                    centre[dim[2]] = 0.0 + k * (r * _SQRT_8_OVER_3)
                    self._spheres.append(SimpleSphere(len(self._spheres), Vec3(0.0, 0.0, 0.0) + Vec3(centre), r))



class CubicBlock(_ClosePackBlock):
    """CubicBlock(dimCount=[nx, ny, nz], radius): ESyS's close-packed block, layers in the sequence ABC (rows along
    x 2r apart, offset by r; rows along z r sqrt(3) apart; layers along y r sqrt(8/3) apart, shifted along z by
    2r/sqrt(3), r/sqrt(3)). Only ESyS's default orientation."""

    NAME = "CubicBlock"

    @staticmethod
    def _offsets(i, j, k, r):
        z_shift = (0.0, 2.0 * _SQRT_1_OVER_3 * r, _SQRT_1_OVER_3 * r)
        return _x_offset(j % 6, k % 6, r), z_shift[k % 3]


class HexagBlock(_ClosePackBlock):
    """HexagBlock(dimCount=[nx, ny, nz], radius): ESyS's hexagonal close packing, layers in the sequence AB
    (HexagBlockIterator: rows along x offset by r where j and k differ in parity; odd layers shifted along z by
    r/sqrt(3)). Only ESyS's default orientation."""

    NAME = "HexagBlock"

    @staticmethod
    def _offsets(i, j, k, r):
        return (r if j % 2 != k % 2 else 0.0), (_SQRT_1_OVER_3 * r if k % 2 == 1 else 0.0)


class Connection:
    """A tagged bond between two particle ids (ESyS's TaggedIdConnection(id1, id2, tag))."""

    def __init__(self, id1, id2, tag):
        self._ids, self._tag = (int(id1), int(id2)), int(tag)

    def getId1(self):
        return self._ids[0]

    def getId2(self):
        return self._ids[1]

    def getTag(self):
        return self._tag


class ConnectionFinder:
    """ConnectionFinder(maxDist, bondTag, pList): a bond between every two spheres of pList whose gap
    d - r1 - r2 is below maxDist (ESyS's DistConnections), smaller id first, sorted."""

    def __init__(self, maxDist=0.01, bondTag=0, pList=()):
        self._max, self._tag, self._connections = float(maxDist), int(bondTag), []
        self._particles = []
        self.addParticles(pList)

    def addParticles(self, pList):
        import numpy as np

        self._particles += list(pList)
        ps = sorted(self._particles, key=lambda p: p.getId())
        pos = np.array([p.getPosn().toList() for p in ps]).reshape(-1, 3)
        rad = np.array([p.getRadius() for p in ps])
        found = []
        for a in range(len(ps)):
            d = np.sqrt(((pos[a + 1:] - pos[a]) ** 2).sum(axis=1))
            for b in np.nonzero(d - rad[a + 1:] - rad[a] < self._max)[0]:
                found.append((ps[a].getId(), ps[a + 1 + b].getId()))
        self._connections = [Connection(i, j, self._tag) for i, j in sorted(found)]

    def __iter__(self):
        return iter(self._connections)

    def __len__(self):
        return len(self._connections)

    def getNumConnections(self):
        return len(self._connections)

    def getNumParticles(self):
        return len(self._particles)
