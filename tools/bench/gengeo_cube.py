#!/usr/bin/python3
"""Packs a bonded cube with GenGeo (python3-gengeo) exactly as the seed paper's base cube cube1.geo
(tests/data/README.md) and writes it as an LSMGeometry .geo file.

    /usr/bin/python3 tools/bench/gengeo_cube.py --side 30 --output bench-inputs/cube30-gengeo.geo
        (or: tools/bench/make_inputs.sh --gengeo); prints one line: particles, bonds, solid fraction, times
    /usr/bin/python3 tools/bench/gengeo_cube.py SIZE RMIN RMAX OUT.geo
        (tools/bench/pack_benchmark.py); prints one JSON line: particles, bonds, solid_fraction, seconds
        (packing + bonding, without writing), exponent (basalt-pack's fitted exponent, docs/packer.md)

The recipe: InsertGenerator3D with radii RMIN-RMAX (default 0.2-1.0 mm), insertFails 1000, maxIterations
1000, tolerance 1e-6, in a box with planes on all six faces, particle tag 1 (as in cube1.geo); bonds between
pairs closer than 1e-5 (bond tag 0), written with outputStyle 1. GenGeo's seeding is off unless --seed: the
packing is then the same on every run of one machine. The 30 mm cube takes tens of minutes. The file is
written to a temporary name and renamed when complete; GenGeo's progress output is silenced (--verbose keeps
it).
"""

import argparse
import json
import math
import os
import sys
import time


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("positional", nargs="*", metavar="SIZE RMIN RMAX OUT.geo",
                   help="the short form: side, radii and output file; prints a JSON line")
    p.add_argument("--side", type=float, help="cube side L, mm")
    p.add_argument("--output", help=".geo file to write")
    p.add_argument("--rmin", type=float, default=0.2)
    p.add_argument("--rmax", type=float, default=1.0)
    p.add_argument("--insert-fails", type=int, default=1000)
    p.add_argument("--max-iterations", type=int, default=1000)
    p.add_argument("--tolerance", type=float, default=1e-6)
    p.add_argument("--bond-tolerance", type=float, default=1e-5)
    p.add_argument("--seed", action="store_true", help="ask GenGeo to randomise its generator")
    p.add_argument("--verbose", action="store_true", help="keep GenGeo's progress output (silenced by default)")
    args = p.parse_args(argv)
    args.json = bool(args.positional)
    if args.positional:
        if len(args.positional) != 4 or args.side is not None or args.output is not None:
            p.error("give either SIZE RMIN RMAX OUT.geo or --side L --output FILE")
        try:
            args.side, args.rmin, args.rmax = (float(v) for v in args.positional[:3])
        except ValueError:
            p.error(f"SIZE RMIN RMAX must be numbers, got {' '.join(args.positional[:3])}")
        args.output = args.positional[3]
    elif args.side is None or args.output is None:
        p.error("give --side and --output (or SIZE RMIN RMAX OUT.geo)")
    if args.side <= 2 * args.rmax or not 0 < args.rmin <= args.rmax:
        p.error(f"need 0 < rmin <= rmax and side > 2 rmax (got side {args.side}, radii {args.rmin}-{args.rmax})")
    return args


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


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        from gengeo import Vector3, BoxWithPlanes3D, Plane, MNTable3D, InsertGenerator3D
    except ImportError:
        print("GenGeo is not available (Debian package python3-gengeo, for /usr/bin/python3). Nothing was done.",
              file=sys.stderr)
        return 3
    out_dir = os.path.dirname(os.path.abspath(args.output))
    if not os.path.isdir(out_dir) or not os.access(out_dir, os.W_OK):
        print(f"error: cannot write {args.output}: directory {out_dir} missing or not writable", file=sys.stderr)
        return 2

    saved_stdout = None
    if not args.verbose:  # GenGeo prints progress from C++ to fd 1
        sys.stdout.flush()
        saved_stdout = os.dup(1)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.close(devnull)
    try:
        t0 = time.perf_counter()
        lo = Vector3(0.0, 0.0, 0.0)
        hi = Vector3(args.side, args.side, args.side)
        box = BoxWithPlanes3D(lo, hi)
        for origin, normal in ((lo, (1, 0, 0)), (lo, (0, 1, 0)), (lo, (0, 0, 1)),
                               (hi, (-1, 0, 0)), (hi, (0, -1, 0)), (hi, (0, 0, -1))):
            box.addPlane(Plane(origin, Vector3(*normal)))
        table = MNTable3D(lo, hi, 2.5 * args.rmax, 1)
        packer = InsertGenerator3D(args.rmin, args.rmax, args.insert_fails, args.max_iterations, args.tolerance,
                                   args.seed)
        packer.generatePacking(box, table, 0, 1)
        t_pack = time.perf_counter() - t0
        table.generateBonds(0, args.bond_tolerance, 0)
        t_bonds = time.perf_counter() - t0
        tmp = args.output + ".tmp"
        table.write(tmp, 1)
        os.replace(tmp, args.output)
    finally:
        if saved_stdout is not None:
            os.dup2(saved_stdout, 1)
            os.close(saved_stdout)
    # Counted from the written file (the Python API exposes no counter for bonds).
    with open(args.output) as f:
        lines = f.read().split("\n")
    i = lines.index("Simple")
    n = int(lines[i + 1])
    radii = [float(line.split()[3]) for line in lines[i + 2:i + 2 + n]]
    nb = int(lines[lines.index("BeginConnect") + 1])
    fraction = sum(4.0 / 3.0 * math.pi * r ** 3 for r in radii) / args.side ** 3
    if args.json:
        print(json.dumps({"particles": n, "bonds": nb, "solid_fraction": fraction, "seconds": t_bonds,
                          "exponent": fitted_exponent(radii, args.rmin, args.rmax)}))
    else:
        print(f"{args.output}: {n} particles, {nb} bonds, solid fraction {fraction:.4f}; "
              f"packing {t_pack:.1f} s, total {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
