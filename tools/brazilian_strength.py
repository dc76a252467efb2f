#!/usr/bin/python3
"""Tensile strength of a Brazilian test (scenes/brazilian.toml) from its fields.csv.

The load F is the mean of the two platens' forces along x (--left, --right: wall names; the platens
close along x at --speed each). sigma_t = 2 F_peak / (pi D t) for a disc of diameter D and thickness t
(the elastic solution for a line load across a disc: the tensile stress at its centre). Prints the peak
load and the step and closure where it occurs, sigma_t, the bonds broken by then (per mode) and at the
end, and with --plot draws load against closure.

  /usr/bin/python3 tools/brazilian_strength.py out/brazilian --diameter 10 --thickness 3 --speed 0.05
"""
import argparse
import csv
import math
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", help="the run's output directory (holds fields.csv)")
    ap.add_argument("--diameter", type=float, required=True)
    ap.add_argument("--thickness", type=float, required=True)
    ap.add_argument("--speed", type=float, required=True, help="each platen's speed")
    ap.add_argument("--left", default="left_platen")
    ap.add_argument("--right", default="right_platen")
    ap.add_argument("--plot", default="", help="PNG file for load against closure")
    a = ap.parse_args()
    if not (a.diameter > 0 and a.thickness > 0 and a.speed > 0):
        sys.exit("brazilian_strength.py: --diameter, --thickness and --speed must be > 0")
    path = f"{a.run}/fields.csv"
    try:
        rows = list(csv.DictReader(open(path)))
    except OSError as e:
        sys.exit(f"brazilian_strength.py: {path}: {e.strerror}")
    cl, cr = f"wall_force_{a.left}_x", f"wall_force_{a.right}_x"
    if not rows or cl not in rows[0] or cr not in rows[0]:
        sys.exit(f"brazilian_strength.py: {path}: needs columns {cl} and {cr}")
    pts = []  # (time, closure, load, row)
    for r in rows:
        if r[cl] in ("", "nan") or r[cr] in ("", "nan"):
            continue
        t = float(r["time"])
        load = 0.5 * (float(r[cr]) - float(r[cl]))  # the right platen is pushed +x, the left -x
        pts.append((t, 2 * a.speed * t, load, r))
    if not pts:
        sys.exit(f"brazilian_strength.py: {path}: no rows with both platen forces")
    peak = max(pts, key=lambda p: p[2])
    if not peak[2] > 0:
        sys.exit(f"brazilian_strength.py: {path}: the platens never carried a load")
    sigma_t = 2 * peak[2] / (math.pi * a.diameter * a.thickness)
    modes = ("tension", "shear", "bending", "torsion")

    def broken(r):
        return ", ".join(f"{m} {r.get('broken_bonds_' + m, '?')}" for m in modes)

    print(f"peak load        {peak[2]:.6g} at step {peak[3]['step']} (closure {peak[1]:.4g}, "
          f"{peak[1] / a.diameter:.4g} of the diameter)")
    print(f"tensile strength sigma_t = 2 F / (pi D t) = {sigma_t:.6g}")
    print(f"broken at peak   {broken(peak[3])}")
    print(f"broken at end    {broken(pts[-1][3])} (step {pts[-1][3]['step']})")
    if a.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 3.5))
        ax.plot([p[1] for p in pts], [p[2] for p in pts], lw=1.2)
        ax.plot([peak[1]], [peak[2]], "o", color="C3")
        ax.set_xlabel("platen closure [mm]")
        ax.set_ylabel("load F [N]")
        ax.set_title(f"Brazilian test: sigma_t = {sigma_t:.3g} N/mm^2")
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)
        print(f"plot             {a.plot}")


if __name__ == "__main__":
    main()
