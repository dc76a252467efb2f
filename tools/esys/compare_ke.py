#!/usr/bin/python3
"""Compares a kinetic-energy series with an ESyS-Particle reference (docs/data/esys_cube1_ekin.csv).

    /usr/bin/python3 tools/esys/compare_ke.py REFERENCE.csv CANDIDATE.csv [--column NAME] [--shift S]
                                             [--tolerance 0.01] [--floor 0.01]

Both files are CSV with a header and a `step` column. ESyS's row n holds the kinetic energy of the
velocities after the kick of step n, i.e. of v((n - 1/2) dt) in velocity-Verlet terms; a velocity-Verlet
code's half-step kinetic energy at step m (v((m + 1/2) dt)) matches ESyS row m + 1: use --shift 1.
Rows where the reference is below --floor times its maximum are skipped in the relative measure (they are
reported in absolute terms). Also prints the first step at which the series differ at all and the first
at which they differ by more than --tolerance (relative, any step with a non-zero reference: the end of
the "chaos window" between two runs). Exit status 1 when the largest relative deviation exceeds --tolerance.
"""

import argparse
import csv
import sys


def load(path, column):
    try:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            if reader.fieldnames is None or "step" not in reader.fieldnames:
                raise SystemExit(f"error: {path}: no 'step' column in the header")
            if column not in reader.fieldnames:
                raise SystemExit(f"error: {path}: no column '{column}' (has {', '.join(reader.fieldnames)})")
            series = {}
            for lineno, row in enumerate(reader, start=2):
                try:
                    series[int(row["step"])] = float(row[column])
                except (TypeError, ValueError):
                    raise SystemExit(f"error: {path}:{lineno}: bad step or {column} value")
            return series
    except OSError as e:
        raise SystemExit(f"error: {path}: {e.strerror}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("reference")
    p.add_argument("candidate")
    p.add_argument("--reference-column", default="kinetic_energy")
    p.add_argument("--column", default="kinetic_energy", help="candidate column")
    p.add_argument("--shift", type=int, default=0, help="candidate step m is compared with reference step m+shift")
    p.add_argument("--tolerance", type=float, default=0.01)
    p.add_argument("--floor", type=float, default=0.01)
    args = p.parse_args()
    ref = load(args.reference, args.reference_column)
    cand = load(args.candidate, args.column)
    pairs = [(m + args.shift, ref[m + args.shift], v) for m, v in cand.items() if m + args.shift in ref]
    if not pairs:
        print("error: the two series share no steps", file=sys.stderr)
        return 2
    peak = max(abs(r) for _, r, _ in pairs)
    rel = [(abs(c - r) / abs(r), s) for s, r, c in pairs if abs(r) >= args.floor * peak]
    small = [(abs(c - r), s) for s, r, c in pairs if abs(r) < args.floor * peak]
    worst, at = max(rel) if rel else (0.0, None)
    mean = sum(d for d, _ in rel) / len(rel) if rel else 0.0
    print(f"{len(pairs)} common steps ({pairs[0][0]}..{pairs[-1][0]} in reference numbering), peak {peak:.6g}")
    print(f"relative deviation over {len(rel)} steps with reference >= {args.floor:g} x peak: "
          f"max {worst:.3e} (reference step {at}), mean {mean:.3e}")
    if small:
        d, s = max(small)
        print(f"absolute deviation where the reference is small: max {d:.3e} (step {s})")
    first_diff = next((s for s, r, c in pairs if c != r), None)
    first_over = next((s for s, r, c in pairs if abs(r) > 0 and abs(c - r) / abs(r) > args.tolerance), None)
    print(f"first step with any difference: {first_diff}; first step with relative deviation > "
          f"{args.tolerance:g}: {first_over}")
    ok = worst <= args.tolerance
    print(f"{'PASS' if ok else 'FAIL'}: tolerance {args.tolerance:g}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
