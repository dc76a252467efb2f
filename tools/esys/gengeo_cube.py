#!/usr/bin/python3
"""Packs a bonded cube of side L with GenGeo (python3-gengeo) and writes it as an LSMGeometry .geo file.

    /usr/bin/python3 tools/esys/gengeo_cube.py --side 30 --output bench-inputs/cube30-gengeo.geo   (or: tools/bench/make_inputs.sh --gengeo)

Same recipe as the paper's reference cube1.geo (BASALT_REFERENCE_DIR; see its README.md): InsertGenerator3D with radii
0.2-1.0 mm, insertFails 1000, maxIterations 1000, tolerance 1e-6, planes on all six faces, particle
tag 1; bonds between pairs closer than 1e-5 (bond tag 0). The 30 mm cube takes tens of minutes.
The file is written to a temporary name and renamed when complete.
"""

import argparse
import os
import sys
import time


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--side", type=float, required=True, help="cube side L, mm")
    p.add_argument("--output", required=True, help=".geo file to write")
    p.add_argument("--rmin", type=float, default=0.2)
    p.add_argument("--rmax", type=float, default=1.0)
    p.add_argument("--insert-fails", type=int, default=1000)
    p.add_argument("--max-iterations", type=int, default=1000)
    p.add_argument("--tolerance", type=float, default=1e-6)
    p.add_argument("--bond-tolerance", type=float, default=1e-5)
    p.add_argument("--seed", action="store_true", help="ask GenGeo to randomise its generator")
    p.add_argument("--verbose", action="store_true", help="keep GenGeo's progress output (silenced by default)")
    args = p.parse_args()
    if args.side <= 2 * args.rmax or not 0 < args.rmin <= args.rmax:
        p.error(f"need 0 < rmin <= rmax and side > 2 rmax (got side {args.side}, radii {args.rmin}-{args.rmax})")
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
    tmp = args.output + ".tmp"
    table.write(tmp, 1)
    os.replace(tmp, args.output)
    if saved_stdout is not None:
        os.dup2(saved_stdout, 1)
        os.close(saved_stdout)
    with open(args.output) as f:
        lines = f.read().split("\n")
    n = int(lines[lines.index("Simple") + 1])
    nb = int(lines[lines.index("BeginConnect") + 1])
    volume = table.getSumVolume(0)
    print(f"{args.output}: {n} particles, {nb} bonds, solid fraction {volume / args.side ** 3:.4f}; "
          f"packing {t_pack:.1f} s, total {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
