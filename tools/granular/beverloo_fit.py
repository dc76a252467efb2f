#!/usr/bin/env python3
"""Fits Beverloo's law W = C rho_b sqrt(g) (D - k d)^(5/2) to hopper discharge runs.

Each run is ORIFICE_DIAMETER:FIELDS_CSV (a basalt-run fields.csv with a mass_below column). The
discharge rate W of a run is the least-squares slope of mass_below against time over the window where
the discharged mass is between --from and --to of its final value (the steady part: after the start
transient, before the silo empties). With rates for several orifices, W^(2/5) is linear in D:
W^(2/5) = (C rho_b sqrt(g))^(2/5) (D - k d), so a straight-line fit gives C rho_b sqrt(g) and k d.
Python 3 standard library only.
"""
import argparse
import csv
import math


def rate(path, lo, hi):
    t, m = [], []
    with open(path) as f:
        for row in csv.DictReader(f):
            if row.get("mass_below", "") == "":
                continue
            t.append(float(row["time"]))
            m.append(float(row["mass_below"]))
    final = m[-1]
    pts = [(a, b) for a, b in zip(t, m) if lo * final <= b <= hi * final]
    n = len(pts)
    if n < 3:
        raise SystemExit(f"{path}: too few points in the window ({n})")
    mt = sum(a for a, _ in pts) / n
    mm = sum(b for _, b in pts) / n
    slope = sum((a - mt) * (b - mm) for a, b in pts) / sum((a - mt) ** 2 for a, _ in pts)
    return slope, final, pts[0][0], pts[-1][0]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help="D:fields.csv")
    ap.add_argument("--d", type=float, required=True, help="mean particle diameter")
    ap.add_argument("--rho-b", type=float, required=True, help="bulk density (solid fraction x particle density)")
    ap.add_argument("--g", type=float, required=True, help="gravity")
    ap.add_argument("--from", dest="lo", type=float, default=0.2)
    ap.add_argument("--to", dest="hi", type=float, default=0.9)
    a = ap.parse_args()
    D, W = [], []
    for r in a.runs:
        d_str, path = r.split(":", 1)
        w, final, t0, t1 = rate(path, a.lo, a.hi)
        D.append(float(d_str))
        W.append(w)
        print(f"D = {float(d_str):g}: W = {w:.6g} (mass/time) over t = {t0:g}..{t1:g}, discharged {final:.6g}")
    y = [w ** 0.4 for w in W]
    n = len(D)
    md, my = sum(D) / n, sum(y) / n
    s = sum((x - md) * (v - my) for x, v in zip(D, y)) / sum((x - md) ** 2 for x in D)
    b = my - s * md
    kd = -b / s
    k = kd / a.d
    C = s ** 2.5 / (a.rho_b * math.sqrt(a.g))
    print(f"fit: W^(2/5) = {s:.6g} (D - {kd:.4g});  k = {k:.3f},  C = {C:.3f}")
    for x, w in zip(D, W):
        pred = C * a.rho_b * math.sqrt(a.g) * max(x - kd, 0) ** 2.5
        print(f"  D = {x:g}: W = {w:.6g}, fit {pred:.6g} ({100 * (pred / w - 1):+.1f} %)")


if __name__ == "__main__":
    main()
