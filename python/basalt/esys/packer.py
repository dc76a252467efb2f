"""esys.lsm.geometry.RandomBoxPacker as ESyS-Particle 2.3.5 packs a box (3-D, no periodic axis): the same spheres,
ids and order, bit for bit (docs/esys.md; tests/python/test_esys_front.py compares with a packing ESyS wrote).

Written from a reading of ESyS's algorithm (Geometry/RandomBoxPacker, CubicBoxPacker, BoxPacker, SphereFitter,
Sphere3d, NeighbourTable, GridIterator; Foundation/Rng), not from its code:

- one random stream for the whole process: Mersenne Twister MT19937 with its default seed 5489, each number a
  32-bit draw divided by 2^32 (Boost's uniform_real on [0, 1)); a second packer in the same script continues the
  stream, as in ESyS;
- first a regular close packing on a grid of spacing cubicPackRadius (its points in ESyS's order), each sphere of a
  random radius, kept where it lies inside the box and overlaps no sphere already kept;
- then random insertion: a random point (z, y, x drawn in that order: ESyS's compiler evaluates its
  Vec3(random, random, random) right to left) and a random radius; its four closest
  spheres found through ESyS's cell table (cells 8 minRadius wide; closest = smallest distance minus radius among
  the spheres of the cells searched); the closest of the six walls; three fitters tried in turn (move the sphere
  onto the surface of its closest neighbour; the sphere touching four neighbours; the sphere touching three
  neighbours and the wall); the first valid fit is inserted; the packing ends once maxInsertFails candidates in a
  row found no fit.

The floating-point operations are done in ESyS's order, so that every coordinate is the same double."""

import math

import numpy as np

from .blocks import SimpleSphere, SphereCollection
from .errors import refuse
from .vec3 import Vec3

_RNG = None  # the process's one stream, as ESyS's static generator
_TWO_32 = 4294967296.0


class _Stream:
    """MT19937 seeded 5489 (numpy's RandomState with an integer seed seeds it the same way), read in blocks."""

    def __init__(self):
        self._state = np.random.RandomState(5489)
        self._buf = []
        self._pos = 0

    def uniform(self):
        if self._pos == len(self._buf):
            self._buf = [v / _TWO_32 for v in self._state.randint(0, 2 ** 32, size=8192, dtype=np.uint32).tolist()]
            self._pos = 0
        u = self._buf[self._pos]
        self._pos += 1
        return u


def _stream():
    global _RNG
    if _RNG is None:
        _RNG = _Stream()
    return _RNG


def _fill_in_4(p1, p2, p3, p4, r1, r2, r3, r4):
    """The sphere touching four spheres (ESyS's Sphere3D::FillIn), or None."""
    x1, y1, z1 = p1
    x2, y2, z2 = p2
    x3, y3, z3 = p3
    x4, y4, z4 = p4
    ax = (y2 - y1) * (y4 - y1)
    ay = (z2 - z1) * (z4 - z1)
    az = (x2 - x1) * (x4 - x1)
    bx = (y3 - y1) * (y4 - y1)
    by = (z3 - z1) * (z4 - z1)
    bz = (x3 - x1) * (x4 - x1)
    cx = (y3 - y1) * (y2 - y1)
    cy = (z3 - z1) * (z2 - z1)
    cz = (x3 - x1) * (x2 - x1)
    Ax = (x3 - x1) * ax - (x2 - x1) * bx
    Ay = (y3 - y1) * ay - (y2 - y1) * by
    Az = (z3 - z1) * az - (z2 - z1) * bz
    Bx = (z4 - z1) * cx - (z2 - z1) * bx
    By = (x4 - x1) * cy - (x2 - x1) * by
    Bz = (y4 - y1) * cz - (y2 - y1) * bz
    Cx = (x4 - x1) * cx - (x2 - x1) * bx
    Cy = (y4 - y1) * cy - (y2 - y1) * by
    Cz = (z4 - z1) * cz - (z2 - z1) * bz
    Dx = (z3 - z1) * ax - (z2 - z1) * bx
    Dy = (x3 - x1) * ay - (x2 - x1) * by
    Dz = (y3 - y1) * az - (y2 - y1) * bz
    Ex = Ax * Bx - Cx * Dx
    Ey = Ay * By - Cy * Dy
    Ez = Az * Bz - Cz * Dz
    if Ex == 0.0 or Ey == 0.0 or Ez == 0.0:
        return None
    a12 = r1 - r2
    b12 = r1 * r1 - r2 * r2 - (x1 * x1 + y1 * y1 + z1 * z1) + (x2 * x2 + y2 * y2 + z2 * z2)
    a13 = r1 - r3
    b13 = r1 * r1 - r3 * r3 - (x1 * x1 + y1 * y1 + z1 * z1) + (x3 * x3 + y3 * y3 + z3 * z3)
    a14 = r1 - r4
    b14 = r1 * r1 - r4 * r4 - (x1 * x1 + y1 * y1 + z1 * z1) + (x4 * x4 + y4 * y4 + z4 * z4)
    alx = (Bx * a13 * ax - Bx * a12 * bx - Dx * a14 * cx + Dx * a12 * bx) / Ex
    aly = (By * a13 * ay - By * a12 * by - Dy * a14 * cy + Dy * a12 * by) / Ey
    alz = (Bz * a13 * az - Bz * a12 * bz - Dz * a14 * cz + Dz * a12 * bz) / Ez
    bex = (Bx * b13 * ax - Bx * b12 * bx - Dx * b14 * cx + Dx * b12 * bx) / (2.0 * Ex)
    bey = (By * b13 * ay - By * b12 * by - Dy * b14 * cy + Dy * b12 * by) / (2.0 * Ey)
    bez = (Bz * b13 * az - Bz * b12 * bz - Dz * b14 * cz + Dz * b12 * bz) / (2.0 * Ez)
    aa = (alx * alx + aly * aly + alz * alz) - 1
    bb = 2.0 * (alx * bex + aly * bey + alz * bez) - 2 * (alx * x4 + aly * y4 + alz * z4) - 2 * r4
    cc = ((bex * bex + bey * bey + bez * bez) + (x4 * x4 + y4 * y4 + z4 * z4)
          - 2.0 * (bex * x4 + bey * y4 + bez * z4) - r4 * r4)
    delta = bb * bb - 4 * aa * cc
    if delta < 0.0:
        return None
    if delta > 0.0:
        delta = math.sqrt(delta)
    if aa != 0.0:
        rs1 = (-bb + delta) / (2 * aa)
        rs2 = (-bb - delta) / (2 * aa)
        if rs1 <= 0 and rs2 <= 0:
            return None
        if rs1 <= 0:
            r = rs2
        elif rs2 <= 0:
            r = rs1
        else:
            r = rs2 if rs2 < rs1 else rs1
    else:
        if bb == 0.0:
            return None
        r = -cc / bb
        if r <= 0.0:
            return None
    return (alx * r + bex, aly * r + bey, alz * r + bez), r


def _fill_in_wall(ip1, ip2, ip3, o, d, r1, r2, r3):
    """The sphere touching three spheres and a plane (origin o, normal d) (ESyS's Sphere3D::FillInWP), or None."""
    ox, oy, oz = o
    x3, y3, z3 = ip3[0] - ox, ip3[1] - oy, ip3[2] - oz
    x2, y2, z2 = ip2[0] - ox, ip2[1] - oy, ip2[2] - oz
    x1, y1, z1 = ip1[0] - ox, ip1[1] - oy, ip1[2] - oz
    n = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    wx, wy, wz = d[0] / n, d[1] / n, d[2] / n
    if (x1 * wx + y1 * wy + z1 * wz) < 0:
        wx, wy, wz = wx * -1.0, wy * -1.0, wz * -1.0
    if (x2 * wx + y2 * wy + z2 * wz) < 0 or (x3 * wx + y3 * wy + z3 * wz) < 0:
        return None
    s = 2.0 * (r2 - r1)
    a12x, a12y = 2.0 * x2 - 2.0 * x1 + s * wx, 2.0 * y2 - 2.0 * y1 + s * wy
    a12z = 2.0 * z2 - 2.0 * z1 + s * wz
    s = 2.0 * (r3 - r1)
    a13x, a13y = 2.0 * x3 - 2.0 * x1 + s * wx, 2.0 * y3 - 2.0 * y1 + s * wy
    a13z = 2.0 * z3 - 2.0 * z1 + s * wz
    p11 = x1 * x1 + y1 * y1 + z1 * z1
    b12 = p11 - (x2 * x2 + y2 * y2 + z2 * z2) + r2 * r2 - r1 * r1
    b13 = p11 - (x3 * x3 + y3 * y3 + z3 * z3) + r3 * r3 - r1 * r1
    cx = a12z * a13y - a13z * a12y
    cy = a12y * a13x - a13y * a12x
    cz = a12z * a13x - a13z * a12x
    dx = b12 * a13y - b13 * a12y
    dy = b12 * a13x - b13 * a12x
    if cy == 0.0:
        return None
    ax, ay, az = dx / cy, -dy / cy, 0.0
    bx, by, bz = cx / cy, -cz / cy, 1.0
    bw = bx * wx + by * wy + bz * wz
    aw_r3 = (ax * wx + ay * wy + az * wz) + r3
    aa = (bx * bx + by * by + bz * bz) - bw * bw
    bb = 2.0 * (bx * (ax - x3) + by * (ay - y3) + bz * (az - z3)) - 2.0 * bw * aw_r3
    cc = ((x3 * x3 + y3 * y3 + z3 * z3) - 2 * (x3 * ax + y3 * ay + z3 * az) + (ax * ax + ay * ay + az * az)
          - aw_r3 * aw_r3)
    delta = bb * bb - 4 * aa * cc
    if delta < 0.0:
        return None
    if delta > 0.0:
        delta = math.sqrt(delta)
    if aa != 0:
        m1z = (-bb + delta) / (2 * aa)
        m2z = (-bb - delta) / (2 * aa)
    else:
        if bb == 0.0:
            return None
        m1z = -cc / bb
        m2z = m1z
    m1 = (ax + bx * m1z, ay + by * m1z, az + bz * m1z)
    m2 = (ax + bx * m2z, ay + by * m2z, az + bz * m2z)
    rs1 = m1[0] * wx + m1[1] * wy + m1[2] * wz
    rs2 = m2[0] * wx + m2[1] * wy + m2[2] * wz
    if rs1 <= 0 and rs2 <= 0:
        return None
    if rs1 <= 0:
        m, r = m2, rs2
    elif rs2 <= 0:
        m, r = m1, rs1
    elif rs1 < rs2:
        m, r = m1, rs1
    else:
        m, r = m2, rs2
    return (ox + m[0], oy + m[1], oz + m[2]), r


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
        self._cubic = float(cubicPackRadius)
        self._max_fails = int(maxInsertFails)
        self._tol = float(tolerance)
        self._spheres = None
        # the cell table: spacing 8 minRadius, floor(size / spacing) cells along each axis (at least one)
        self._cell = 8.0 * self._rmin
        self._dims = [max(int(math.floor((self._hi[a] - self._lo[a]) / self._cell)), 1) for a in range(3)]
        self._cells = [[] for _ in range(self._dims[0] * self._dims[1] * self._dims[2])]
        self._x, self._y, self._z, self._r = [], [], [], []  # the spheres, by id
        self._xa, self._ya, self._za, self._ra = (np.zeros(0) for _ in range(4))  # the same, for numpy

    # -- ESyS's Python methods
    def generate(self):
        """Packs the box; called again, packs again around the spheres already there (as ESyS: the grid, then
        random insertion), the ids going on."""
        self._cubic_packing()
        self._random_fill()
        spheres = self._spheres or []  # the spheres of an earlier generate() stay the same objects
        for i in range(len(spheres), len(self._x)):
            spheres.append(SimpleSphere(i, Vec3(self._x[i], self._y[i], self._z[i]), self._r[i]))
        self._spheres = spheres

    def getSimpleSphereCollection(self):
        return SphereCollection(self._spheres or [])

    def getSimpleSphereIterator(self):
        return iter(list(self._spheres or []))

    def getNumSpheres(self):
        return len(self._spheres or [])

    # -- the cell table
    def _index(self, x, y, z):
        lo, c, d = self._lo, self._cell, self._dims
        i = min(max(math.floor((x - lo[0]) / c), 0), d[0] - 1)
        j = min(max(math.floor((y - lo[1]) / c), 0), d[1] - 1)
        k = min(max(math.floor((z - lo[2]) / c), 0), d[2] - 1)
        return i, j, k

    def _cell_range(self, x, y, z, radius):
        i0, j0, k0 = self._index(x - radius, y - radius, z - radius)
        i1, j1, k1 = self._index(x + radius, y + radius, z + radius)
        dy, dz = self._dims[1], self._dims[2]
        cells = self._cells
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                base = (i * dy + j) * dz
                for k in range(k0, k1 + 1):
                    yield cells[base + k]

    def _insert(self, x, y, z, r):
        n = len(self._x)
        if n == len(self._xa):
            for name in ("_xa", "_ya", "_za", "_ra"):
                a = np.zeros(max(2 * n, 1024))
                a[:n] = getattr(self, name)
                setattr(self, name, a)
        self._xa[n], self._ya[n], self._za[n], self._ra[n] = x, y, z, r
        self._x.append(x)
        self._y.append(y)
        self._z.append(z)
        self._r.append(r)
        for c in self._cell_range(x, y, z, r):
            c.append(n)

    # -- validity
    def _fits_box(self, x, y, z, r):
        lo, hi, t = self._lo, self._hi, self._tol
        for p in ((x - r, y - 0, z - 0), (x + r, y + 0, z + 0), (x - 0, y - r, z - 0), (x + 0, y + r, z + 0),
                  (x - 0, y - 0, z - r), (x + 0, y + 0, z + r)):
            if not (lo[0] <= p[0] + t and lo[1] <= p[1] + t and lo[2] <= p[2] + t
                    and hi[0] >= p[0] - t and hi[1] >= p[1] - t and hi[2] >= p[2] - t):
                return False
        return True

    def _fits_neighbours(self, x, y, z, r):
        t = self._tol
        X, Y, Z, R = self._x, self._y, self._z, self._r
        for c in self._cell_range(x, y, z, r + t):
            for n in c:
                dx, dy, dz = x - X[n], y - Y[n], z - Z[n]
                s = (r + R[n]) - t
                if dx * dx + dy * dy + dz * dz < s * s:
                    return False
        return True

    def _valid(self, x, y, z, r):
        return (self._rmin <= r <= self._rmax and self._fits_box(x, y, z, r)
                and self._fits_neighbours(x, y, z, r))

    # -- the two stages
    def _cubic_packing(self):
        rng = _stream()
        R = self._cubic
        size = [self._hi[a] - self._lo[a] for a in range(3)]
        nx = max(1, int(round((size[0] - (R / 4.0)) / (R * 2.0))))
        ny = max(1, int(round(size[1] / (R * 2.0 * math.sqrt(2.0 / 3.0)))))
        nz = max(1, int(round(size[2] / (R * math.sqrt(3.0)))))
        if nz > 1 and ny > 1:
            nx -= 1
        x0, y0, z0 = self._lo[0] + R, self._lo[1] + R, self._lo[2] + R
        for i in range(nx):
            for j in range(nz):
                for k in range(ny):
                    x = x0 + (float(i) + 0.5 * float(j % 2) + 0.5 * float(k % 2)) * R * 2.0
                    y = y0 + (float(k) * 2.0 * math.sqrt(2.0 / 3.0)) * R
                    z = z0 + ((float(j) + float(k % 2) / 3.0) * math.sqrt(3.0)) * R
                    r = self._rmin + (self._rmax - self._rmin) * rng.uniform()
                    if self._fits_box(x, y, z, r) and self._fits_neighbours(x, y, z, r):
                        self._insert(x, y, z, r)

    def _unique(self, x, y, z, radius):
        """The ids of the spheres in the cells within radius of (x, y, z), each once, ascending (ESyS sorts its
        list by address, which follows the ids)."""
        cells = list(self._cell_range(x, y, z, radius))
        if len(cells) == 1:
            return cells[0]  # ids are appended in ascending order
        return sorted(set().union(*cells))

    def _closest(self, x, y, z, r):
        """The (up to) four closest spheres, by distance minus radius, among those ESyS's table offers."""
        t = self._tol
        ids = self._unique(x, y, z, t)
        if len(ids) < 4:
            ids = self._unique(x, y, z, r + t)
            if len(ids) < 4:
                ids = self._unique(x, y, z, self._rmax + t)
        if len(ids) <= 1:
            return list(ids)
        a = np.array(ids)
        dx, dy, dz = self._xa[a] - x, self._ya[a] - y, self._za[a] - z
        key = np.sqrt(dx * dx + dy * dy + dz * dz) - self._ra[a]
        return a[np.argsort(key, kind="stable")[:4]].tolist()  # ties: the lower id first

    def _closest_wall(self, x, y, z):
        """(origin, normal, distance, axis) of the closest wall; on ties the first in ESyS's order y, x, z (min
        then max)."""
        lo, hi = self._lo, self._hi
        best = None
        for axis, sign, origin in ((1, 1.0, lo), (1, -1.0, hi), (0, 1.0, lo), (0, -1.0, hi), (2, 1.0, lo),
                                   (2, -1.0, hi)):
            d = abs((x, y, z)[axis] - origin[axis])
            if best is None or d < best[2]:
                normal = [0.0, 0.0, 0.0]
                normal[axis] = sign
                best = (origin, normal, d, axis)
        return best

    def _random_fill(self):
        rng = _stream()
        lo, hi = self._lo, self._hi
        rmin, rmax, max_fails = self._rmin, self._rmax, self._max_fails
        last_fails = 0
        while last_fails < max_fails:
            fails = 0
            fit = None
            while fit is None and fails < max_fails:
                # z first: ESyS's compiled Vec3(random, random, random) evaluates its arguments right to left
                z = lo[2] + (hi[2] - lo[2]) * rng.uniform()
                y = lo[1] + (hi[1] - lo[1]) * rng.uniform()
                x = lo[0] + (hi[0] - lo[0]) * rng.uniform()
                r = rmin + (rmax - rmin) * rng.uniform()
                nb = self._closest(x, y, z, r)
                wall = self._closest_wall(x, y, z)
                fit = self._fit_surface(x, y, z, r, nb)
                if fit is None:
                    fit = self._fit_four(x, y, z, nb, wall)
                if fit is None:
                    fit = self._fit_wall(x, y, z, nb, wall)
                fails += 1
            last_fails = fails
            if fit is None:
                break
            self._insert(*fit[0], fit[1])

    # -- the fitters
    def _fit_surface(self, x, y, z, r, nb):
        if nb:
            n = nb[0]
            nx, ny, nz, nr = self._x[n], self._y[n], self._z[n], self._r[n]
            dx, dy, dz = x - nx, y - ny, z - nz
            if math.sqrt(dx * dx + dy * dy + dz * dz) < r + nr:
                d = math.sqrt(dx * dx + dy * dy + dz * dz)
                if d > 0.0:
                    s = nr + r
                    x, y, z = nx + (dx / d) * s, ny + (dy / d) * s, nz + (dz / d) * s
        return ((x, y, z), r) if self._valid(x, y, z, r) else None

    def _moved_inside(self, x, y, z, n):
        """The candidate's centre, moved onto the surface of neighbour n if it lies inside n; None if at n's
        centre."""
        nx, ny, nz, nr = self._x[n], self._y[n], self._z[n], self._r[n]
        dx, dy, dz = x - nx, y - ny, z - nz
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        if not d > 0.0:
            return None
        if d < nr:
            s = nr / d
            return nx + dx * s, ny + dy * s, nz + dz * s
        return x, y, z

    def _gap(self, x, y, z, n):
        dx, dy, dz = x - self._x[n], y - self._y[n], z - self._z[n]
        return math.sqrt(dx * dx + dy * dy + dz * dz) - self._r[n]

    def _fit_four(self, x, y, z, nb, wall):
        if len(nb) <= 3:
            return None
        p = self._moved_inside(x, y, z, nb[0])
        if p is None:
            return None
        # the distance to the wall chosen for the candidate, from the (maybe moved) centre
        wall_p = abs(p[wall[3]] - wall[0][wall[3]])
        if not wall_p > self._gap(*p, nb[3]):
            return None
        X, Y, Z, R = self._x, self._y, self._z, self._r
        a, b, c, d = nb
        fit = _fill_in_4((X[a], Y[a], Z[a]), (X[b], Y[b], Z[b]), (X[c], Y[c], Z[c]), (X[d], Y[d], Z[d]),
                         R[a], R[b], R[c], R[d])
        if fit is None or not self._valid(*fit[0], fit[1]):
            return None
        return fit

    def _fit_wall(self, x, y, z, nb, wall):
        if len(nb) < 3:
            return None
        n0 = nb[0]
        dx, dy, dz = x - self._x[n0], y - self._y[n0], z - self._z[n0]
        if not math.sqrt(dx * dx + dy * dy + dz * dz) > 0.0:
            return None
        if len(nb) > 3 and not wall[2] < self._gap(x, y, z, nb[3]):
            return None
        origin, normal = wall[0], wall[1]
        X, Y, Z, R = self._x, self._y, self._z, self._r
        a, b, c = nb[:3]
        fit = _fill_in_wall((X[a], Y[a], Z[a]), (X[b], Y[b], Z[b]), (X[c], Y[c], Z[c]), origin, normal,
                            R[a], R[b], R[c])
        if fit is None or not self._valid(*fit[0], fit[1]):
            return None
        return fit
