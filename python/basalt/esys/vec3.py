"""esys.lsm.util's Vec3 and BoundingBox, as ESyS-Particle's Python API has them (pure Python)."""

import math


def _g(v):
    """A number as C++'s default ostream prints it (6 significant digits): what ESyS writes and str() shows."""
    return "%g" % v


class Vec3:
    """A 3-vector: Vec3(x, y, z) or Vec3(sequence); indexing, + - * /, dot, cross, norm, rotate, toList."""

    __slots__ = ("_v",)

    def __init__(self, x=0.0, y=None, z=None):
        if y is None and z is None and not isinstance(x, (int, float)):
            x, y, z = x  # Vec3(v) or Vec3([x, y, z])
        self._v = [float(x), float(0.0 if y is None else y), float(0.0 if z is None else z)]

    def __getitem__(self, i):
        if not -3 <= i < 3:
            raise IndexError("Index out of range")
        return self._v[i]

    def __setitem__(self, i, value):
        if not -3 <= i < 3:
            raise IndexError("Index out of range")
        self._v[i] = float(value)

    def __len__(self):
        return 3

    def __iter__(self):
        return iter(self._v)

    def __eq__(self, other):
        return isinstance(other, Vec3) and self._v == other._v

    def __add__(self, o):
        return Vec3(*(a + b for a, b in zip(self._v, o))) if isinstance(o, Vec3) else Vec3(*(a + o for a in self._v))

    def __sub__(self, o):
        return Vec3(*(a - b for a, b in zip(self._v, o))) if isinstance(o, Vec3) else Vec3(*(a - o for a in self._v))

    def __mul__(self, s):
        return Vec3(*(a * s for a in self._v))

    __rmul__ = __mul__

    def __truediv__(self, s):
        return Vec3(*(a / s for a in self._v))

    def __neg__(self):
        return Vec3(*(-a for a in self._v))

    def dot(self, v):
        a, b = self._v, list(v)
        return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]

    def cross(self, v):
        a, b = self._v, list(v)
        return Vec3(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])

    def norm(self):
        x, y, z = self._v
        return math.sqrt(x * x + y * y + z * z)

    def rotate(self, axis, axisPt):
        """This point rotated about the axis through axisPt by |axis| radians, with ESyS's formula and sense
        (Foundation/vec3.hpp: r cos + n (n.r)(1 - cos) + (r x n) sin; (1, 0, 0) about +z by pi/6 gives
        (0.866, -0.5, 0)), operation for operation."""
        axis, axisPt = Vec3(axis), Vec3(axisPt)
        phi = axis.norm()
        if not phi > 0.0:
            return Vec3(self)
        r = self - axisPt
        n = axis / phi
        c = math.cos(phi)
        return r * c + n * (n.dot(r) * (1 - c)) + r.cross(n) * math.sin(phi) + axisPt

    def toList(self):
        return list(self._v)

    def toTuple(self):
        return tuple(self._v)

    def __str__(self):
        return " ".join(_g(a) for a in self._v)  # ESyS's operator<<: "x y z", 6 significant digits

    def __repr__(self):
        return "Vec3(%r, %r, %r)" % tuple(self._v)


class BoundingBox:
    """BoundingBox(minPt, maxPt): an axis-aligned box (ESyS's spatial domain)."""

    def __init__(self, minPt=None, maxPt=None):
        self._min = Vec3(minPt if minPt is not None else (0, 0, 0))
        self._max = Vec3(maxPt if maxPt is not None else (0, 0, 0))

    def getMinPt(self):
        return Vec3(self._min)

    def getMaxPt(self):
        return Vec3(self._max)

    def getSizes(self):
        return self._max - self._min

    def getCentre(self):
        return (self._min + self._max) * 0.5

    def __str__(self):
        return f"{self._min} {self._max}"
