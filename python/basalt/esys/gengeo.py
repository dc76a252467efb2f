"""GenGeo's box packing rebuilt in Python for `from gengeo import *` inside `python3 -m basalt.esys`
(docs/esys.md, "GenGeo"): Vector3, Plane, Sphere, BoxWithPlanes3D, MNTable3D and InsertGenerator3D.

Written from what Debian's GenGeo 1.4 does (measured on its output and read from its machine code): the same
random numbers (glibc's rand() from its default seed, as GenGeo never seeds it), the same seeding lattice,
trial points, simplex fit of each new sphere to its four nearest objects, overlap checks, ids (one global
counter bumped by every sphere GenGeo constructs, fits that fail included) and .geo file, each floating-point
operation in GenGeo's order, so that the spheres come out bit for bit.
"""

import math

import numpy as np

from .errors import refuse

OFFER = ("Basalt reproduces GenGeo's BoxWithPlanes3D packing by InsertGenerator3D (docs/esys.md, \"GenGeo\"); "
         "Basalt packs other shapes with basalt.pack (box, cylinder, sphere, mesh; lattice=True for a regular one; "
         "bonds between touching spheres), or run the script with GenGeo itself and read its .geo with "
         "readGeometry")
# GenGeo 1.4's other public names (its volumes, packers and tables): refused by the shim's gengeo
REFUSED = [
    "AGenerator2D", "AGenerator3D", "AVolume", "AVolume2D", "AVolume3D", "BoxWithJointSet", "BoxWithLines2D",
    "BoxWithLines2DSubVol", "CircMNTable2D", "CircMNTable3D", "CircMNTableXY2D", "CircleVol", "ClippedCircleVol",
    "ClippedSphereVol", "ConvexPolyWithJointSet", "ConvexPolyhedron", "CylinderVol", "CylinderWithJointSet",
    "DifferenceVol", "DogBone", "EllipsoidVol", "FullCircMNTable3D", "HGrainGenerator2D",
    "HexAggregateInsertGenerator2D", "HexAggregateInsertGenerator2DRand", "HexAggregateInsertGenerator3D",
    "InsertGenerator2D", "IntersectionVol", "Line2D", "LineSegment2D", "LineSet", "MNTable2D",
    "MeshVolWithJointSet", "MeshVolume", "MeshVolume2D", "PolygonWithLines2D", "Shape", "ShapeList",
    "SphereSectionVol", "SphereVol", "SphereVolWithJointSet", "TriBox", "TriPatchSet", "TriWithLines2D",
    "UnionVol"]


class _RefuseOthers:
    """GenGeo's methods this class does not have are refused by name (NotSupportedError), not AttributeError."""

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        refuse(f"{type(self).__name__}.{name}", OFFER)


_RAND_MAX = 2147483647.0
_SMALL = 1e-7          # GenGeo's MNTable3D::s_small_value
_FOUR_THIRDS_PI = 4.188790133333333  # GenGeo's 4/3 pi, with pi as 3.1415926


class _GlibcRand:
    """glibc's rand() (TYPE_3 additive feedback generator), from srand(seed)."""

    def __init__(self, seed=1):
        r = [0] * 34
        r[0] = seed if seed else 1
        for i in range(1, 31):
            hi, lo = divmod(r[i - 1], 127773)
            word = 16807 * lo - 2836 * hi
            if word < 0:
                word += 2147483647
            r[i] = word
        for i in range(31, 34):
            r[i] = r[i - 31]
        self.r = r
        for _ in range(310):
            self._next()

    def _next(self):
        r = self.r
        v = (r[-31] + r[-3]) & 0xFFFFFFFF
        r.append(v)
        if len(r) > 4096:
            del r[:-34]
        return v >> 1

    def __call__(self):
        return self._next()


_rand = _GlibcRand()
_next_id = [0]  # GenGeo's Sphere::s_current_id


def _new_id():
    i = _next_id[0]
    _next_id[0] = i + 1
    return i


def _ceil(x):
    return int(math.ceil(x))


class Vector3:
    __slots__ = ("x", "y", "z")

    def __init__(self, x=0.0, y=0.0, z=0.0):
        self.x, self.y, self.z = float(x), float(y), float(z)

    def X(self):
        return self.x

    def Y(self):
        return self.y

    def Z(self):
        return self.z

    def __add__(self, o):
        return Vector3(self.x + o.x, self.y + o.y, self.z + o.z)

    def __sub__(self, o):
        return Vector3(self.x - o.x, self.y - o.y, self.z - o.z)

    def __mul__(self, s):
        return Vector3(self.x * s, self.y * s, self.z * s)

    __rmul__ = __mul__

    def __truediv__(self, s):
        return Vector3(self.x / s, self.y / s, self.z / s)

    def __neg__(self):
        return Vector3(-self.x, -self.y, -self.z)

    def __eq__(self, o):
        return isinstance(o, Vector3) and (self.x, self.y, self.z) == (o.x, o.y, o.z)

    def __getitem__(self, i):
        return (self.x, self.y, self.z)[i]

    def norm(self):
        return math.sqrt((self.x * self.x + self.y * self.y) + self.z * self.z)

    def __repr__(self):
        return f"{self.x:g} {self.y:g} {self.z:g}"

    __str__ = __repr__


def _vec(v):
    return v if isinstance(v, Vector3) else Vector3(*v)


class Plane:
    """A plane through `origin` with normal `normal` (normalised as GenGeo does)."""

    def __init__(self, origin, normal):
        origin, normal = _vec(origin), _vec(normal)
        self.p = (origin.x, origin.y, origin.z)
        n = math.sqrt((normal.x * normal.x + normal.y * normal.y) + normal.z * normal.z)
        self.n = (normal.x / n, normal.y / n, normal.z / n)

    def getDist(self, q):
        p, n = self.p, self.n
        return abs(((q[0] - p[0]) * n[0] + (q[1] - p[1]) * n[1]) + (q[2] - p[2]) * n[2])


class Sphere:
    """A sphere; constructing one takes the next id of GenGeo's global counter, as GenGeo's does."""

    __slots__ = ("c", "r", "id", "tag")

    def __init__(self, centre=None, radius=0.0):
        if centre is None:  # GenGeo's default constructor: id 0, no counter
            self.c, self.r, self.id, self.tag = (0.0, 0.0, 0.0), 0.0, 0, 0
            return
        centre = _vec(centre)
        self.c = (centre.x, centre.y, centre.z)
        self.r = float(radius)
        self.id = _new_id()
        self.tag = 0

    def Centre(self):
        return Vector3(*self.c)

    Center = Centre

    def Radius(self):
        return self.r

    def Id(self):
        return self.id

    def Tag(self):
        return self.tag

    def setTag(self, tag):
        self.tag = int(tag)

    def setId(self, i):
        self.id = int(i)
        if _next_id[0] < self.id:
            _next_id[0] = self.id

    def getDist(self, q):
        c = self.c
        dx, dy, dz = q[0] - c[0], q[1] - c[1], q[2] - c[2]
        return math.sqrt((dx * dx + dy * dy) + dz * dz) - self.r


class BoxWithPlanes3D(_RefuseOthers):
    """An axis-aligned box to fill; planes added with addPlane also bound the spheres (touching them)."""

    def __init__(self, minPoint, maxPoint):
        lo, hi = _vec(minPoint), _vec(maxPoint)
        self.lo = (lo.x, lo.y, lo.z)
        self.hi = (hi.x, hi.y, hi.z)
        self.planes = []

    def addPlane(self, plane):
        self.planes.append(plane)

    def getBoundingBox(self):
        return Vector3(*self.lo), Vector3(*self.hi)

    def getAPoint(self, ivol=0):
        lo, hi = self.lo, self.hi
        x = lo[0] + (_rand() / _RAND_MAX) * (hi[0] - lo[0])
        y = lo[1] + (_rand() / _RAND_MAX) * (hi[1] - lo[1])
        z = lo[2] + (_rand() / _RAND_MAX) * (hi[2] - lo[2])
        return (x, y, z)

    def _is_in(self, c, r):
        lo, hi = self.lo, self.hi
        if not (c[0] > lo[0] + r and hi[0] - r > c[0] and c[1] > lo[1] + r and hi[1] - r > c[1]
                and c[2] > lo[2] + r and hi[2] - r > c[2]):
            return False
        d = r + r
        for p in self.planes:
            if not d > r:
                break
            d = p.getDist(c)
        return d > r

    def isIn(self, sphere):
        return self._is_in(sphere.c, sphere.r)


class MNTable3D(_RefuseOthers):
    """GenGeo's neighbour table: cells of gridSize around the box (one layer of empty cells outside), each
    holding its spheres per group in insertion order; the .geo lists them cell by cell."""

    def __init__(self, minPoint, maxPoint, gridSize, numGroups=1):
        lo, hi = _vec(minPoint), _vec(maxPoint)
        g = float(gridSize)
        self.cell = g
        self.ngroups = int(numGroups)
        self.n = (_ceil((hi.x - lo.x) / g) + 2, _ceil((hi.y - lo.y) / g) + 2, _ceil((hi.z - lo.z) / g) + 2)
        self.origin = (lo.x - g, lo.y - g, lo.z - g)
        self.lo = (lo.x, lo.y, lo.z)
        self.hi = (lo.x + g * (self.n[0] - 2), lo.y + g * (self.n[1] - 2), lo.z + g * (self.n[2] - 2))
        self.cells = {}   # index -> [list of spheres per group]
        self._hoods = {}  # the spheres around a point, cached until the next insertion (_closest4)
        self.bonds = {}   # tag -> set of (id1, id2)
        print("nx,ny,nz: %d , %d , %d" % self.n)

    # -- cells
    def _index(self, q):
        o, g = self.origin, self.cell
        ix = math.floor((q[0] - o[0]) / g)
        iy = math.floor((q[1] - o[1]) / g)
        iz = math.floor((q[2] - o[2]) / g)
        nx, ny, nz = self.n
        if 0 < ix < nx - 1 and 0 < iy < ny - 1 and 0 < iz < nz - 1:
            return (ix * ny + iy) * nz + iz
        return -1

    def _around(self, q):
        g = self.cell
        for i in (-1.0, 0.0, 1.0):
            x = g * i + q[0]
            for j in (-1.0, 0.0, 1.0):
                y = g * j + q[1]
                for k in (-1.0, 0.0, 1.0):
                    idx = self._index((x, y, k * g + q[2]))
                    if idx != -1:
                        cell = self.cells.get(idx)
                        if cell is not None:
                            yield cell

    def _near(self, c, dist, gid):
        for cell in self._around(c):
            for s in cell[gid]:
                if not dist < s.getDist(c):
                    return True
        return False

    def _axis_cells(self, q, axis):
        o, g = self.origin[axis], self.cell
        return tuple(math.floor(((g * i + q[axis]) - o) / g) for i in (-1.0, 0.0, 1.0))

    def _closest4(self, q):
        """The spheres nearest to q as GenGeo's getSpheresClosestTo(q, 4) orders them: (distance, sphere) by
        distance, an equal distance kept once (the first of the cells in GenGeo's order), at most 4."""
        key = (self._axis_cells(q, 0), self._axis_cells(q, 1), self._axis_cells(q, 2))
        hood = self._hoods.get(key)
        if hood is None:
            hood = self._hoods[key] = self._hood(key)
        xyzr, spheres = hood
        if not spheres:
            return []
        dx = q[0] - xyzr[0]
        dy = q[1] - xyzr[1]
        dz = q[2] - xyzr[2]
        d = np.sqrt((dx * dx + dy * dy) + dz * dz) - xyzr[3]
        order = np.argsort(d, kind="stable") if len(spheres) > 1 else (0,)
        out = []
        last = None
        for i in order:
            di = float(d[i])
            if di != last:
                out.append((di, spheres[i]))
                last = di
                if len(out) == 4:
                    break
        return out

    def _hood(self, key):
        """The spheres of the 27 cells of `key` (x, y and z cell numbers) in GenGeo's order: cells x, y, z
        from -1 to 1, then groups, then insertion order."""
        nx, ny, nz = self.n
        spheres = []
        for ix in key[0]:
            for iy in key[1]:
                for iz in key[2]:
                    if 0 < ix < nx - 1 and 0 < iy < ny - 1 and 0 < iz < nz - 1:
                        cell = self.cells.get((ix * ny + iy) * nz + iz)
                        if cell is not None:
                            for group in cell:
                                spheres.extend(group)
        xyzr = np.array([s.c + (s.r,) for s in spheres], dtype=np.float64).T.copy() if spheres else None
        return xyzr, spheres

    def _store(self, s, gid):
        idx = self._index(s.c)
        nx, ny, nz = self.n
        ix, rest = divmod(idx, ny * nz)
        iy, iz = divmod(rest, nz)
        stale = [key for key in self._hoods if ix in key[0] and iy in key[1] and iz in key[2]]
        for key in stale:  # the neighbourhoods holding the sphere's cell
            del self._hoods[key]
        cell = self.cells.get(idx)
        if cell is None:
            cell = self.cells[idx] = [[] for _ in range(self.ngroups)]
        cell[gid].append(s)

    def insert(self, sphere, gid=0):
        if self._index(sphere.c) == -1 or not 0 <= gid < self.ngroups:
            return False
        self._store(_copy(sphere), gid)
        return True

    def insertChecked(self, sphere, gid=0, tol=_SMALL):
        if self._index(sphere.c) == -1 or not 0 <= gid < self.ngroups:
            return False
        if self._near(sphere.c, sphere.r - (_SMALL + tol), gid):
            return False
        self._store(_copy(sphere), gid)
        return True

    def checkInsertable(self, sphere, gid=0):
        if self._index(sphere.c) == -1 or not 0 <= gid < self.ngroups:
            return False
        return not self._near(sphere.c, sphere.r - _SMALL, gid)

    # -- queries
    def _spheres(self, gid=None):
        for idx in sorted(self.cells):
            cell = self.cells[idx]
            for g, group in enumerate(cell):
                if gid is None or g == gid:
                    yield from group

    def getSphereListFromGroup(self, groupID):
        return list(self._spheres(groupID))

    def getNumParticles(self, groupID=-1):
        return sum(1 for _ in self._spheres(None if groupID < 0 else groupID))

    def getSumVolume(self, groupID=0):
        """The spheres' volume, summed per cell, then over the cells (GenGeo's order)."""
        total = 0.0
        for idx in sorted(self.cells):
            cell_sum = 0.0
            for s in self.cells[idx][groupID]:
                cell_sum += ((s.r * _FOUR_THIRDS_PI) * s.r) * s.r
            total += cell_sum
        return total

    # -- bonds
    def generateBonds(self, groupID=0, tol=1e-5, bondTag=0):
        print("MNTable3D::generateBonds(", groupID, ",", tol, ",", bondTag, ")")
        pairs = self.bonds.setdefault(int(bondTag), set())
        for a, b in self._touching(groupID, tol):
            pairs.add((a.id, b.id) if a.id < b.id else (b.id, a.id))

    def _touching(self, groupID, tol, every_neighbour=False):
        """The pairs of groupID with |d - r1 - r2| < tol (r1 + r2), over the cell pairs GenGeo visits: each cell
        with itself and with the neighbours whose offset (di, dj, dk) sums to more than 0. The three offsets
        summing to 0 ((0, 1, -1), (1, 0, -1), (1, -1, 0) and their opposites) are never visited, so touching
        spheres across those cell edges get no bond (as GenGeo's .geo shows). generateClusterBonds visits all 26
        neighbours (every_neighbour)."""
        nx, ny, nz = self.n
        offsets = [0] + [(di * ny + dj) * nz + dk for di in (-1, 0, 1) for dj in (-1, 0, 1) for dk in (-1, 0, 1)
                         if di + dj + dk > 0 or (every_neighbour and (di, dj, dk) != (0, 0, 0))]
        for idx in sorted(self.cells):
            mine = self.cells[idx][groupID]
            if not mine:
                continue
            for off in offsets:
                cell = self.cells.get(idx + off)
                if cell is None:
                    continue
                for a in mine:
                    for b in cell[groupID]:
                        if a is b:
                            continue
                        dx, dy, dz = a.c[0] - b.c[0], a.c[1] - b.c[1], a.c[2] - b.c[2]
                        rr = a.r + b.r
                        if rr * tol > abs(math.sqrt((dx * dx + dy * dy) + dz * dz) - rr):
                            yield a, b

    def tagParticlesToClosest(self, groupID, seedGroupID):
        """Each sphere of groupID takes the tag of the closest sphere (centre to centre) of seedGroupID."""
        seeds = list(self._spheres(seedGroupID))
        if not seeds:
            return
        xyz = np.array([s.c for s in seeds])
        tags = [s.tag for s in seeds]
        for s in self._spheres(groupID):
            dx = s.c[0] - xyz[:, 0]
            dy = s.c[1] - xyz[:, 1]
            dz = s.c[2] - xyz[:, 2]
            s.tag = tags[int(np.argmin((dx * dx + dy * dy) + dz * dz))]

    def removeParticlesInGroup(self, groupID):
        for cell in self.cells.values():
            cell[groupID] = []
        self._hoods.clear()

    def generateClusterBonds(self, groupID, tol, bondTag1, bondTag2):
        """Bonds between touching spheres of groupID: bondTag1 when both carry the same tag, bondTag2 when not."""
        same = self.bonds.setdefault(int(bondTag1), set())
        diff = self.bonds.setdefault(int(bondTag2), set())
        for a, b in self._touching(groupID, tol, every_neighbour=True):
            (same if a.tag == b.tag else diff).add((a.id, b.id) if a.id < b.id else (b.id, a.id))

    # -- output
    def write(self, fileName, outputStyle=1):
        """outputStyle 1: the .geo file ESyS reads (readGeometry); 2: GenGeo's VTK .vtu (spheres as points with
        radius, id and tag, bonds as lines with their tag), both as GenGeo writes them."""
        style = int(outputStyle)
        if style not in (1, 2):
            refuse(f"MNTable3D.write(..., {outputStyle})", "outputStyle 1 (the .geo file ESyS reads) and 2 (the "
                   ".vtu) are written; Basalt's own files come from basalt.pack and basalt-run (docs/formats.md)")
        spheres = list(self._spheres())
        bonds = [(a, b, t) for t in sorted(self.bonds) for a, b in sorted(self.bonds[t])]  # by tag, then ids
        text = self._geo(spheres, bonds) if style == 1 else self._vtu(spheres, bonds)
        with open(fileName, "w") as f:
            f.write(text)

    def _geo(self, spheres, bonds):
        out = ["LSMGeometry 1.2",
               "BoundingBox " + " ".join(_g10(v) for v in self.lo + self.hi),
               "PeriodicBoundaries 0 0 0", "Dimension 3D", "BeginParticles", "Simple", str(len(spheres))]
        for s in spheres:
            out.append(" ".join(_g10(v) for v in s.c + (s.r,)) + f" {s.id} {s.tag}")
        out += ["EndParticles", "BeginConnect", str(len(bonds))]
        out += [f"{a} {b} {t}" for a, b, t in bonds]
        out.append("EndConnect")
        return "\n".join(out) + "\n"

    @staticmethod
    def _vtu(spheres, bonds):
        index = {s.id: i for i, s in enumerate(spheres)}
        head = '<DataArray type="%s" Name="%s" NumberOfComponents="1" format="ascii">'
        out = ['<VTKFile type="UnstructuredGrid" version="0.1">', "<UnstructuredGrid>",
               f'<Piece NumberOfPoints="{len(spheres)}" NumberOfCells="{len(bonds)}">', "<Points>",
               '<DataArray NumberOfComponents="3" type="Float64" format="ascii">',
               "".join(_g10(v) + " " for s in spheres for v in s.c), "</DataArray>", "</Points>",
               '<PointData Scalars="radius">', head % ("Float64", "radius"),
               "".join(_g10(s.r) + " " for s in spheres), "</DataArray>", head % ("Int32", "particleID"),
               "".join(f"{s.id} " for s in spheres), "</DataArray>", head % ("Int32", "particleTag"),
               "".join(f"{s.tag} " for s in spheres), "</DataArray>", "</PointData>", "<Cells>",
               '<DataArray type="Int32" NumberOfComponents="1" Name="connectivity" format="ascii">']
        out += [f"{index[a]} {index[b]}" for a, b, t in bonds]
        out += ["</DataArray>", '<DataArray type="Int32" NumberOfComponents="1" Name="offsets" format="ascii">']
        out += [str(2 * (i + 1)) for i in range(len(bonds))]
        out += ["</DataArray>", '<DataArray type="UInt8" NumberOfComponents="1" Name="types" format="ascii">']
        out += ["3"] * len(bonds)
        out += ["</DataArray>", "</Cells>", "<CellData>", head % ("Int32", "bondTag")]
        out += [str(t) for a, b, t in bonds]
        out += ["</DataArray>", "</CellData>", "</Piece>", "</UnstructuredGrid>", "</VTKFile>"]
        return "\n".join(out) + "\n"


def _g10(v):
    return "%.10g" % v


def _copy(s):
    c = Sphere.__new__(Sphere)
    c.c, c.r, c.id, c.tag = s.c, s.r, s.id, s.tag
    return c


# -- the simplex fit (GenGeo's simplex search on the spread of the four distances): basalt._core.gengeo_fit,
# compiled (python/src/gengeo.cpp), 100 times quicker than the same steps in Python
def _fit(objs, start, max_iter, prec):
    from .._core_loader import core
    spec = [(True, o.p + o.n) if isinstance(o, Plane) else (False, o.c + (o.r, 0.0, 0.0)) for o in objs]
    x, y, z, r = core().gengeo_fit(spec, start, max_iter, prec)
    return Sphere(Vector3(x, y, z), r)


class InsertGenerator3D(_RefuseOthers):
    """GenGeo's insertion packer: a lattice of seed spheres, then spheres fitted to their four nearest
    neighbours (spheres or the box's planes) at random points until maxTries points in a row found no room."""

    def __init__(self, minRadius, maxRadius, insertFails, maxIterations, tolerance, seed=False):
        self.rmin = float(minRadius)
        self.rmax = float(maxRadius)
        self.max_tries = float(insertFails)
        self.max_iter = int(maxIterations)
        self.prec = float(tolerance)
        self.old_seeding = False
        self.default_tag = 0
        if seed:  # GenGeo: srand() from the clock's microseconds, a different packing on every run
            import time
            global _rand
            _rand = _GlibcRand(int(time.time() * 1e6) % 1000000)

    def setOldSeeding(self, old):
        """GenGeo's first seeding: the lattice spheres without their random shift, radii up to the room."""
        self.old_seeding = bool(old)

    def setNextTag(self, tag):
        self.default_tag = int(tag)

    def generatePacking(self, vol, ntable, gid=0, tag=-1, shapes=None):
        if shapes is not None:
            refuse("InsertGenerator3D.generatePacking(..., ShapeList)", "spheres only")
        if not isinstance(vol, BoxWithPlanes3D):
            refuse(f"InsertGenerator3D.generatePacking({type(vol).__name__})", "BoxWithPlanes3D only")
        if tag == -1:
            tag = self.default_tag
        self._seed(vol, ntable, gid, tag)
        self._fill(vol, ntable, gid, tag)

    def _seed(self, vol, table, gid, tag):
        print("InsertGenerator3D::seedParticles")
        lo, hi = vol.lo, vol.hi
        print("bbx: %g %g %g - %g %g %g" % (lo + hi))
        rmin, rmax = self.rmin, self.rmax
        imax = int(math.ceil((hi[0] - lo[0]) / (rmax + rmax)))
        jmax = int(math.ceil((hi[1] - lo[1]) / (rmax * 1.7320508075688772)))
        kmax = int(math.ceil((hi[2] - lo[2]) / ((rmax + rmax) * 0.816496580927726)))
        for i in range(imax + 1):
            for j in range(jmax + 1):
                fx = float(j & 1) * 0.5 + float(i)
                for k in range(kmax + 1):
                    kk = float(k & 1)
                    px = ((((kk * 0.5 + fx) * rmax) * 2.0 + lo[0]) + rmax) + 1e-5
                    py = ((((kk / 3.0 + float(j)) * 1.7320508075688772) * rmax + lo[1]) + rmax) + 1e-5
                    pz = (((float(k) * 2.0 * 0.816496580927726) * rmax + lo[2]) + rmax) + 1e-5
                    a = hi[0] - px
                    b = px - lo[0]
                    dx = a if a < b else b
                    a = hi[1] - py
                    b = py - lo[1]
                    dy = a if a < b else b
                    a = hi[2] - pz
                    b = pz - lo[2]
                    dz = a if a < b else b
                    de = dx if dx < dy else dy
                    de = de if de < dz else dz
                    if not de > rmin:
                        continue
                    top = de if rmax > de else rmax
                    if self.old_seeding:
                        r = (_rand() / _RAND_MAX) * (top - rmin) + rmin
                        jitter = 0.0
                    else:
                        r = (_rand() / _RAND_MAX) * ((top - rmin) * 0.5) + rmin
                        jitter = top - r
                    u1 = _rand()
                    u2 = _rand()
                    x = ((u1 / _RAND_MAX) * 2.0 + -1.0) * jitter + px
                    y = ((u2 / _RAND_MAX) * 2.0 + -1.0) * jitter + py
                    z = ((_rand() / _RAND_MAX) * 2.0 - 1.0) * jitter + pz
                    s = Sphere(Vector3(x, y, z), r)
                    if vol.isIn(s) and table.checkInsertable(s, gid):
                        s.tag = tag
                        table.insertChecked(s, gid, _SMALL)

    def _fill(self, vol, table, gid, tag):
        fails = 0
        total = 0
        inserted = 0
        since = 0
        rmin, rmax, prec, max_iter = self.rmin, self.rmax, self.prec, self.max_iter
        while fails < self.max_tries:
            p = vol.getAPoint(0)
            objs = {}
            for d, s in table._closest4(p):
                objs[d] = s
            for pl in vol.planes:
                objs.setdefault(pl.getDist(p), pl)
            if len(objs) >= 4:
                four = [objs[d] for d in sorted(objs)[:4]]
                s = _fit(four, p, max_iter, prec)
                ok = s.r > rmin and rmax > s.r
                inside = vol.isIn(s)
                if ok and inside:
                    s.tag = tag
                    if table.insertChecked(s, gid, _SMALL):
                        inserted += 1
                        total += fails
                        since += fails
                        if inserted % 100 == 0:
                            print("inserted %d at avg. %g" % (inserted, since / 100.0))
                            since = 0
                        fails = 0
                        continue
            fails += 1
        print("total tries: %d" % total)


__all__ = ["Vector3", "Plane", "Sphere", "BoxWithPlanes3D", "MNTable3D", "InsertGenerator3D"]
