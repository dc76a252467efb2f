#!/usr/bin/python3
"""Packs a cube with GenGeo exactly as the seed paper's base cube (shared/reference/README.md):
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
    print(json.dumps({"particles": n, "bonds": nb, "solid_fraction": vol / size ** 3, "seconds": seconds}))


if __name__ == "__main__":
    main()
