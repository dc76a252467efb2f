#!/usr/bin/python3
"""Deposit metrics of a granular run from a particle-positions CSV (columns id,x,y,z,r; extra columns ignored;
.csv or .csv.gz).

    /usr/bin/python3 tools/esys/deposit_metrics.py docs/data/esys-granular/positions_base.csv [more.csv ...]

Prints, per file: particle count, centre of mass (x, y, z) with mass proportional to r^3 (uniform density),
and the front: the 95th percentile of x over the particles (unweighted; linear interpolation between order
statistics, numpy's default: position p (n - 1) in the sorted list), plus max x. --json for machine output.
Used for the ESyS reference (docs/reference-runs.md, "Granular reference run") and for Basalt's run of
scenes/granular-esys.toml, so both go through the same arithmetic.
"""

import argparse
import csv
import gzip
import json
import math
import sys


def percentile(sorted_values, p):
    pos = p * (len(sorted_values) - 1)
    lo = math.floor(pos)
    hi = min(lo + 1, len(sorted_values) - 1)
    return sorted_values[lo] + (sorted_values[hi] - sorted_values[lo]) * (pos - lo)


def metrics(path):
    opener = gzip.open if path.endswith(".gz") else open
    with opener(path, "rt") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError(f"{path}: no particle rows")
    for col in ("x", "y", "z", "r"):
        if col not in rows[0]:
            raise ValueError(f"{path}: missing column '{col}' (need id,x,y,z,r)")
    xs = [float(r["x"]) for r in rows]
    ys = [float(r["y"]) for r in rows]
    zs = [float(r["z"]) for r in rows]
    ms = [float(r["r"]) ** 3 for r in rows]
    mt = sum(ms)
    com = [sum(m * c for m, c in zip(ms, cs)) / mt for cs in (xs, ys, zs)]
    sx = sorted(xs)
    return {"file": path, "particles": len(rows), "com_x": com[0], "com_y": com[1], "com_z": com[2],
            "x_p95": percentile(sx, 0.95), "x_max": sx[-1]}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("files", nargs="+")
    p.add_argument("--json", action="store_true")
    args = p.parse_args()
    out = []
    for path in args.files:
        try:
            out.append(metrics(path))
        except (OSError, ValueError, KeyError) as e:
            print(f"error: {e}", file=sys.stderr)
            return 2
    if args.json:
        print(json.dumps(out, indent=1))
    else:
        for m in out:
            print(f"{m['file']}: {m['particles']} particles, centre of mass ({m['com_x']:.4f}, {m['com_y']:.4f}, "
                  f"{m['com_z']:.4f}), front x_p95 {m['x_p95']:.4f}, x_max {m['x_max']:.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
