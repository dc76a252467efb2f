#!/usr/bin/python3
"""Packs a cube with GenGeo exactly as the seed paper's base cube (tests/data/README.md):
InsertGenerator3D(insertFails=1000, maxIterations=1000, tolerance=1e-6), bonds with tolerance 1e-5.
Usage: gengeo_cube.py SIZE RMIN RMAX OUT.geo   -> prints one JSON line: particles, bonds, solid_fraction, seconds.
Run with /usr/bin/python3 (Debian's python3-gengeo)."""
import json
import math
import sys
import time

from gengeo import BoxWithPlanes3D, InsertGenerator3D, MNTable3D, Plane, Vector3


def main():
    size, rmin, rmax = (float(a) for a in sys.argv[1:4])
    out = sys.argv[4]
    lo, hi = Vector3(0.0, 0.0, 0.0), Vector3(size, size, size)
    t0 = time.perf_counter()
    box = BoxWithPlanes3D(minPoint=lo, maxPoint=hi)
    box.addPlane(Plane(lo, Vector3(1.0, 0.0, 0.0)))
    box.addPlane(Plane(lo, Vector3(0.0, 1.0, 0.0)))
    box.addPlane(Plane(lo, Vector3(0.0, 0.0, 1.0)))
    box.addPlane(Plane(hi, Vector3(-1.0, 0.0, 0.0)))
    box.addPlane(Plane(hi, Vector3(0.0, -1.0, 0.0)))
    box.addPlane(Plane(hi, Vector3(0.0, 0.0, -1.0)))
    table = MNTable3D(minPoint=lo, maxPoint=hi, gridSize=2.5 * rmax, numGroups=1)
    packer = InsertGenerator3D(minRadius=rmin, maxRadius=rmax, insertFails=1000, maxIterations=1000,
                               tolerance=1.0e-6)
    packer.generatePacking(volume=box, ntable=table, groupID=0, tag=0)
    table.generateBonds(groupID=0, tolerance=1.0e-5, bondID=0)
    seconds = time.perf_counter() - t0
    table.write(fileName=out, outputStyle=1)
    # Count from the written file (the Python API exposes no counters for bonds).
    with open(out) as f:
        lines = f.read().split("\n")
    i = lines.index("BeginParticles")
    n = int(lines[i + 2])
    vol = sum(4.0 / 3.0 * math.pi * float(l.split()[3]) ** 3 for l in lines[i + 3:i + 3 + n])
    j = lines.index("BeginConnect")
    nb = int(lines[j + 1])
    radii = [float(l.split()[3]) for l in lines[i + 3:i + 3 + n]]
    print(json.dumps({"particles": n, "bonds": nb, "solid_fraction": vol / size ** 3, "seconds": seconds,
                      "exponent": fitted_exponent(radii, rmin, rmax)}))


def fitted_exponent(radii, rmin, rmax, bins=16):
    """basalt-pack's definition (docs/packer.md): 16 bins equally spaced in ln r over [rmin, rmax]; minus the
    slope of the least-squares line through (ln r_centre, ln count), each non-empty bin weighted by its count."""
    l0, l1 = math.log(rmin), math.log(rmax)
    width = (l1 - l0) / bins
    counts = [0] * bins
    for r in radii:
        counts[min(bins - 1, max(0, int(math.floor((math.log(r) - l0) / width))))] += 1
    pts = [(l0 + width * (k + 0.5), math.log(c), c) for k, c in enumerate(counts) if c > 0]
    sw = sum(w for _, _, w in pts)
    sx = sum(w * x for x, _, w in pts)
    sy = sum(w * y for _, y, w in pts)
    sxx = sum(w * x * x for x, _, w in pts)
    sxy = sum(w * x * y for x, y, w in pts)
    return -(sw * sxy - sx * sy) / (sw * sxx - sx * sx)


if __name__ == "__main__":
    main()
