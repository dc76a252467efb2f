#!/usr/bin/python3
"""Stress-strain curve of a uniaxial compression run (scenes/ucs.toml) from its fields.csv.

stress = mean of the two platens' axial forces / initial cross-section (pi R^2, or --area);
strain = platen closure / initial height, the closure from the platens' positions when fields.csv has
wall_position of both, else from their constant speed (each moves at --speed towards the other, so
closure = 2 speed t). Prints Young's modulus (slope of stress against
strain between 10 % and 50 % of the peak, least squares), the UCS (peak stress), the strain at peak and
the broken bonds by mode at peak and at the end; with --plot draws the curve (matplotlib).

  /usr/bin/python3 tools/ucs_curve.py out/ucs --height 20 --radius 5 --speed 0.03 --plot docs/img/ucs.png
"""
import argparse
import csv
import math
import sys


def read_curve(run, height, area, speed=None, top="top_wall", bottom="bottom_wall"):
    """(strain, stress, modes) rows of a run's fields.csv. The closure is height minus the platens' distance
    when fields.csv has wall_position_<name>_z of both (platens starting at the specimen's ends; right with
    ramped motions too), else 2 speed t (speed: each platen's)."""
    path = f"{run}/fields.csv"
    try:
        rows = list(csv.DictReader(open(path)))
    except OSError as e:
        sys.exit(f"ucs_curve.py: {path}: {e.strerror}")
    ctop, cbot = f"wall_force_{top}_z", f"wall_force_{bottom}_z"
    ptop, pbot = f"wall_position_{top}_z", f"wall_position_{bottom}_z"
    if not rows or ctop not in rows[0] or cbot not in rows[0]:
        sys.exit(f"ucs_curve.py: {path}: needs columns {ctop} and {cbot}")
    positions = ptop in rows[0] and pbot in rows[0]
    if not positions and speed is None:
        sys.exit(f"ucs_curve.py: {path}: give --speed, or save wall_position of both platens")
    strain, stress, modes = [], [], []
    for r in rows:
        if r[ctop] == "" or r[cbot] == "":
            continue
        # Particles push the top platen up (+z) and the bottom one down (-z).
        f = 0.5 * (float(r[ctop]) - float(r[cbot]))
        if positions:
            closure = height - (float(r[ptop]) - float(r[pbot]))
        else:
            closure = 2 * speed * float(r["time"])
        strain.append(closure / height)
        stress.append(f / area)
        modes.append([float(r.get(f"broken_bonds_{m}", "nan") or "nan") for m in ("tension", "shear", "bending", "torsion")])
    return strain, stress, modes


def summarize(strain, stress):
    """Young's modulus (least-squares slope between 10 % and 50 % of the peak, before it), the UCS (peak
    stress), the strain at the peak, its row and the points used for the slope, as a dict."""
    k = max(range(len(stress)), key=lambda i: stress[i])
    peak = stress[k]
    sel = [i for i in range(k + 1) if 0.1 * peak <= stress[i] <= 0.5 * peak]
    if len(sel) < 2:
        sys.exit("ucs_curve.py: too few points between 10 % and 50 % of the peak")
    mx = sum(strain[i] for i in sel) / len(sel)
    my = sum(stress[i] for i in sel) / len(sel)
    E = sum((strain[i] - mx) * (stress[i] - my) for i in sel) / sum((strain[i] - mx) ** 2 for i in sel)
    return {"E": E, "ucs": peak, "strain_at_peak": strain[k], "peak_row": k, "slope_points": len(sel)}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", help="the run's output directory (holds fields.csv)")
    ap.add_argument("--height", type=float, required=True, help="initial specimen height")
    ap.add_argument("--radius", type=float, help="cylinder radius (area pi R^2)")
    ap.add_argument("--area", type=float, help="cross-section area (instead of --radius)")
    ap.add_argument("--speed", type=float, help="each platen's speed (not needed when fields.csv has "
                    "wall_position of both platens)")
    ap.add_argument("--top", default="top_wall")
    ap.add_argument("--bottom", default="bottom_wall")
    ap.add_argument("--plot", default="", help="PNG file for the curve")
    ap.add_argument("--csv", default="", help="write strain,stress rows here")
    a = ap.parse_args()
    if (a.radius is None) == (a.area is None):
        sys.exit("ucs_curve.py: give exactly one of --radius and --area")
    area = a.area if a.area is not None else math.pi * a.radius**2
    strain, stress, modes = read_curve(a.run, a.height, area, a.speed, a.top, a.bottom)
    s = summarize(strain, stress)
    k, peak, E = s["peak_row"], s["ucs"], s["E"]
    print(f"points              {len(stress)}")
    print(f"Young's modulus     {E:.6g}   (10-50 % of peak, {s['slope_points']} points)")
    print(f"UCS (peak stress)   {peak:.6g}")
    print(f"strain at peak      {strain[k]:.6g}")
    print(f"broken at peak      tension {modes[k][0]:g}, shear {modes[k][1]:g}, bending {modes[k][2]:g}, torsion {modes[k][3]:g}")
    print(f"broken at end       tension {modes[-1][0]:g}, shear {modes[-1][1]:g}, bending {modes[-1][2]:g}, torsion {modes[-1][3]:g}")
    if a.csv:
        with open(a.csv, "w") as out:
            out.write("strain,stress\n")
            for e, s in zip(strain, stress):
                out.write(f"{e:.8g},{s:.8g}\n")
    if a.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot([e * 100 for e in strain], stress, lw=1)
        ax.plot([strain[k] * 100], [peak], "o", label=f"UCS {peak:.4g} at {strain[k]*100:.3g} %")
        ax.set_xlabel("axial strain (%)")
        ax.set_ylabel("axial stress (N/mm$^2$)")
        ax.legend()
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)


if __name__ == "__main__":
    main()
