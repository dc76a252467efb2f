#!/usr/bin/python3
"""Tiles a .geo packing n x n x n times (ids and bonds offset per tile; no bonds across tiles) to make
bigger benchmark geometries from GenGeo's cube1.geo: n = 2 gives a 30 mm cube (71,584 particles, the
size of the paper's 30 mm case), n = 5 about 1.1 M particles for the memory measurement.

    /usr/bin/python3 tools/bench/wave_tile_geo.py $BASALT_REFERENCE_DIR/cube1.geo 2 out/cube1-tiled2.geo
"""
import sys


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    src, n, dst = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    with open(src) as f:
        lines = f.read().split("\n")
    box = [float(v) for v in lines[1].split()[1:7]]
    side = [box[3] - box[0], box[4] - box[1], box[5] - box[2]]
    i = lines.index("BeginParticles")
    count = int(lines[i + 2])
    particles = [l.split() for l in lines[i + 3:i + 3 + count]]
    j = lines.index("BeginConnect", i)
    nb = int(lines[j + 1])
    bonds = [l.split() for l in lines[j + 2:j + 2 + nb]]
    stride = max(int(p[4]) for p in particles) + 1
    out = [lines[0],
           "BoundingBox {} {} {} {} {} {}".format(box[0], box[1], box[2], box[0] + n * side[0], box[1] + n * side[1],
                                                  box[2] + n * side[2]),
           lines[2], lines[3], "BeginParticles", "Simple", str(count * n ** 3)]
    tiles = [(a, b, c) for a in range(n) for b in range(n) for c in range(n)]
    for t, (a, b, c) in enumerate(tiles):
        for x, y, z, r, pid, tag in particles:
            out.append("{:.10g} {:.10g} {:.10g} {} {} {}".format(float(x) + a * side[0], float(y) + b * side[1],
                                                                float(z) + c * side[2], r, int(pid) + t * stride, tag))
    out += ["EndParticles", "BeginConnect", str(nb * n ** 3)]
    for t in range(len(tiles)):
        for p, q, tag in bonds:
            out.append("{} {} {}".format(int(p) + t * stride, int(q) + t * stride, tag))
    out += ["EndConnect", ""]
    with open(dst, "w") as f:
        f.write("\n".join(out))
    print(f"{dst}: {count * n ** 3} particles, {nb * n ** 3} bonds")


if __name__ == "__main__":
    main()
