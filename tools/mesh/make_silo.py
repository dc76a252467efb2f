#!/usr/bin/python3
"""Writes a flat-bottomed cylindrical silo as an ASCII STL mesh wall (docs/mesh-walls.md).

The silo is an open surface: a cylinder of the given diameter and height (open at the top) standing on
z = 0, its axis the z axis, and a flat bottom at z = 0 with a circular orifice of the given diameter at
the centre. Circles are polygons of --facets sides, all three rings at the same angles so that the
side and the bottom share the vertices of the outer ring. Triangles are wound counter-clockwise seen
from inside the silo (the right-hand normals point towards the grains), which a one-sided wall needs;
two-sided walls (the default for open surfaces) do not care. Units are those of the scene (the mesh
carries none). Every coordinate is printed with 17 significant digits, so the reader welds the shared
vertices exactly.

    tools/mesh/make_silo.py --diameter 40 --height 60 --orifice 8 --facets 64 -o scenes/meshes/silo.stl
"""
import argparse
import math
import sys


def silo_triangles(diameter, height, orifice, facets):
    R, r0 = diameter / 2, orifice / 2
    ring = [(math.cos(2 * math.pi * k / facets), math.sin(2 * math.pi * k / facets)) for k in range(facets)]
    outer = [(R * c, R * s, 0.0) for c, s in ring]
    top = [(R * c, R * s, float(height)) for c, s in ring]
    hole = [(r0 * c, r0 * s, 0.0) for c, s in ring]
    tris = []
    for k in range(facets):
        j = (k + 1) % facets
        # Side: normals point inwards (towards the axis).
        tris.append((outer[k], top[k], outer[j]))
        tris.append((outer[j], top[k], top[j]))
        # Bottom annulus: normals point up (+z).
        tris.append((hole[k], outer[k], outer[j]))
        tris.append((hole[k], outer[j], hole[j]))
    return tris


def write_stl(tris, out, name):
    g = lambda x: repr(float(x))
    out.write(f"solid {name}\n")
    for a, b, c in tris:
        u = [b[i] - a[i] for i in range(3)]
        w = [c[i] - a[i] for i in range(3)]
        n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
        ln = math.sqrt(sum(x * x for x in n))
        n = [x / ln for x in n]
        out.write(f"  facet normal {' '.join(g(x) for x in n)}\n    outer loop\n")
        for p in (a, b, c):
            out.write(f"      vertex {' '.join(g(x) for x in p)}\n")
        out.write("    endloop\n  endfacet\n")
    out.write(f"endsolid {name}\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--diameter", type=float, default=40.0, help="inner diameter of the silo (default 40)")
    ap.add_argument("--height", type=float, default=60.0, help="height of the cylinder wall (default 60)")
    ap.add_argument("--orifice", type=float, default=8.0, help="diameter of the orifice in the bottom (default 8)")
    ap.add_argument("--facets", type=int, default=64, help="sides of each circle (default 64)")
    ap.add_argument("-o", "--output", default="-", help="STL file to write (default: standard output)")
    a = ap.parse_args()
    if not (a.diameter > 0 and a.height > 0 and 0 < a.orifice < a.diameter and a.facets >= 3):
        ap.error("need diameter > 0, height > 0, 0 < orifice < diameter and facets >= 3")
    tris = silo_triangles(a.diameter, a.height, a.orifice, a.facets)
    name = f"silo_d{a.diameter:g}_h{a.height:g}_o{a.orifice:g}_f{a.facets}"
    if a.output == "-":
        write_stl(tris, sys.stdout, name)
    else:
        with open(a.output, "w") as f:
            write_stl(tris, f, name)


if __name__ == "__main__":
    main()
