#!/usr/bin/python3
"""Compares Basalt's run of scenes/ucs-esys.toml with ESyS-Particle's reference run of the same test
(tools/esys/ucs_esys.py; docs/validation-rock.md, "Same input as ESyS-Particle").

    basalt-run scenes/ucs-esys.toml --output out/ucs-esys
    /usr/bin/python3 tools/esys/compare_ucs.py out/ucs-esys [--esys docs/data/esys-ucs/ucs_base.csv]
        [--perturbed docs/data/esys-ucs/ucs_perturbed.csv] [--plot docs/img/ucs_esys.png]
    (--basalt-run build/bin/basalt-run runs the scene into that folder first: the ctest solver_esys_ucs)

Platen force F = the mean of the two walls' axial forces (ESyS's wall "Force" saver points the other way
from Basalt's wall_force). Basalt's row of step n holds the forces ESyS computes in its step n + 1 (both
from the particles after step n), so ESyS's force is interpolated linearly to step n + 1 between its rows.
Checks (exit 1 when one fails):
  - F within --force-tol (1 %) of ESyS's at every saved step where ESyS's F is at least --floor (5 %) of
    its peak, up to the step where ESyS's F first reaches half its peak;
  - the peak force within 5 %, and the broken bonds (initial count - bond_count) at the reference's peak
    step within 10 % (the count at each run's own peak is printed, not checked: see compare()).
The peak checks need an ESyS series that passes its peak (F falls below 90 % of its maximum afterwards);
on a series that stops before, they are reported as not available and the exit status is 2 when nothing
failed. The same numbers for ESyS against its run with one particle moved by 1e-12 (--perturbed), or for
Basalt against its own such run (--basalt-perturbed), show what the chaos of fracture alone does.
"""

import argparse
import csv
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

DATA = os.path.join(HERE, "..", "..", "docs", "data", "esys-ucs")


def esys_series(path):
    """step -> (F, bond_count, kinetic_energy) from ucs_esys.py's ucs.csv."""
    out = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            out[int(r["step"])] = (0.5 * (float(r["bottom_fz"]) - float(r["top_fz"])), float(r["bond_count"]),
                                   float(r["kinetic_energy"]))
    return out


def basalt_series(run_dir):
    c = bt.read_fields(os.path.join(run_dir, "fields.csv"))
    if "wall_force_top_wall_z" not in c:
        return {}
    out = {}
    for s, top, bottom, bonds, ke in zip(c["step"], c["wall_force_top_wall_z"], c["wall_force_bottom_wall_z"],
                                         c["bond_count"], c["kinetic_energy"]):
        if top == top:  # saved at this step (an empty cell is nan)
            out[s] = (0.5 * (top - bottom), bonds, ke)
    return out


def at(series, step):
    """Linear interpolation of a series (sorted dict of step -> tuple) at step."""
    if step in series:
        return series[step]
    keys = sorted(series)
    lo = max((k for k in keys if k < step), default=None)
    hi = min((k for k in keys if k > step), default=None)
    if lo is None or hi is None:
        return None
    w = (step - lo) / (hi - lo)
    return tuple(a + w * (b - a) for a, b in zip(series[lo], series[hi]))


def peak_of(series):
    """(step, F, bonds) at the largest F, and whether the series has passed it (F < 90 % of it later)."""
    steps = sorted(series)
    k = max(steps, key=lambda s: series[s][0])
    passed = any(series[s][0] < 0.9 * series[k][0] for s in steps if s > k)
    return k, series[k][0], series[k][1], passed


def compare(ref, other, shift, floor, tol, label):
    """Prints the comparison of other (rows at step n) against ref (at n + shift); returns (ok, complete)."""
    if not ref or not other:
        print(f"{label}: FAIL an empty series")
        return False, True
    kp, fp, bp, passed = peak_of(ref)
    ko, fo, bo, passed_o = peak_of(other)
    # The window: up to half of the reference's peak; while the reference stops before its peak, up to half
    # of the compared run's (complete) peak, or the reference's end.
    fwin = fp if passed else (fo if passed_o else fp)
    half = min((s for s in sorted(ref) if ref[s][0] >= 0.5 * fwin), default=None)
    if half is None:
        print(f"{label}: the reference ends at step {max(ref)} below half of the peak: the window stops there")
        half = max(ref)
    initial = ref[min(ref)][1]
    worst, where, n = 0.0, None, 0
    for s in sorted(other):
        e = at(ref, s + shift)
        if e is None or s + shift > half or e[0] < floor * fwin:
            continue
        d = abs(other[s][0] - e[0]) / e[0]
        n += 1
        if d > worst:
            worst, where = d, s
    ok = n > 0 and worst < tol
    print(f"{label}: platen force from {floor:.0%} to half of the peak ({0.5 * fwin:.6g} N, reference step {half}): "
          f"max relative deviation {worst:.3e} at step {where} over {n} rows -> {'ok' if ok else 'FAIL'}")
    if not passed:
        print(f"{label}: the reference ends at step {max(ref)} before its peak (largest F {fp:.6g} at step {kp}): "
              "peak and broken bonds not compared")
        return ok, False
    ko, fo, bo, passed_o = peak_of(other)
    if not passed:
        print(f"{label}: the reference ends at step {max(ref)} before its peak (largest F {fp:.6g} at step {kp}): "
              "peak and broken bonds not compared")
        return ok, False
    if not passed_o:
        print(f"{label}: FAIL the compared run ends at step {max(other)} before its peak")
        return False, True
    dp = abs(fo - fp) / fp
    broken_ref, initial_other = initial - bp, other[min(other)][1]
    # Broken bonds at the reference's peak step (the compared run's row of that step; Basalt's rows are
    # shifted by one step). Not at each run's own peak: the force stays within 1 % of its peak for ~500
    # steps while ~300 bonds break, so where in that plateau the largest value falls decides the count
    # (ESyS against itself with a 1e-12 nudge: 880 against 780 at the own peaks, 12.8 %).
    e = at(other, kp - shift)
    if e is None:
        print(f"{label}: FAIL the compared run has no row at the reference's peak step {kp}")
        return False, True
    broken_other = initial_other - e[1]
    db = abs(broken_other - broken_ref) / max(broken_ref, 1.0)
    own = abs((initial_other - bo) - broken_ref) / max(broken_ref, 1.0)
    ok_p, ok_b = dp < 0.05, db < 0.10
    print(f"{label}: peak force {fo:.6g} at step {ko} against {fp:.6g} at step {kp}: {dp:.2%} -> "
          f"{'ok' if ok_p else 'FAIL'} (5 %)")
    print(f"{label}: broken bonds at the reference's peak (step {kp}) {broken_other:.0f} against "
          f"{broken_ref:.0f}: {db:.2%} -> {'ok' if ok_b else 'FAIL'} (10 %); at each run's own peak "
          f"{initial_other - bo:.0f} against {broken_ref:.0f} ({own:.2%}, not checked)")
    return ok and ok_p and ok_b, True


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir", help="Basalt's output directory (fields.csv)")
    ap.add_argument("--esys", default=os.path.join(DATA, "ucs_base.csv"))
    ap.add_argument("--perturbed", default=os.path.join(DATA, "ucs_perturbed.csv"))
    ap.add_argument("--basalt-perturbed", default="",
                    help="a Basalt run of the scene with one particle moved by 1e-12: Basalt against itself")
    ap.add_argument("--basalt-run", default="", help="run scenes/ucs-esys.toml with this binary into RUN_DIR first")
    ap.add_argument("--floor", type=float, default=0.05)
    ap.add_argument("--force-tol", type=float, default=0.01)
    ap.add_argument("--plot", default="")
    args = ap.parse_args()
    if args.basalt_run:
        import subprocess
        scene = bt.repo_path("scenes", "ucs-esys.toml")
        cmd = [args.basalt_run, scene, "--output", args.run_dir, "--quiet"]
        if subprocess.call(cmd) != 0:
            print("FAIL: " + " ".join(cmd) + " exited non-zero")
            return 1
    try:
        ref = esys_series(args.esys)
        mine = basalt_series(args.run_dir)
    except OSError as e:
        print(f"error: {e.filename}: {e.strerror}", file=sys.stderr)
        return 2
    if not ref or not mine:
        print(f"error: no rows in {args.esys if not ref else os.path.join(args.run_dir, 'fields.csv')}",
              file=sys.stderr)
        return 2
    ok, complete = compare(ref, mine, 1, args.floor, args.force_tol, "Basalt vs ESyS")
    pert = None
    if os.path.exists(args.perturbed):
        pert = esys_series(args.perturbed)
        compare(ref, pert, 0, args.floor, args.force_tol, "ESyS perturbed 1e-12 vs ESyS")
    if args.basalt_perturbed:
        compare(mine, basalt_series(args.basalt_perturbed), 0, args.floor, args.force_tol,
                "Basalt perturbed 1e-12 vs Basalt")
    last = min(max(ref) - 1, max(mine))
    for s in (1000, 2000, 5000, 10000, 15000, 20000, last):
        e = at(ref, s + 1)
        if s in mine and e is not None and s <= last:
            print(f"  step {s:6d}: F ESyS {e[0]:10.5g}  Basalt {mine[s][0]:10.5g} ({mine[s][0] / e[0] - 1:+.2e});"
                  f"  bonds {e[1]:.0f} / {mine[s][1]:.0f};  KE {e[2]:.5g} / {mine[s][2]:.5g}")
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
        rs = sorted(ref)
        ax[0].plot(rs, [ref[s][0] for s in rs], label="ESyS-Particle 2.3.5")
        if pert:
            ps = sorted(pert)
            ax[0].plot(ps, [pert[s][0] for s in ps], ":", label="ESyS, one particle moved by 1e-12")
        ms = sorted(s for s in mine if s <= max(rs))
        ax[0].plot(ms, [mine[s][0] for s in ms], "--", label="Basalt")
        ax[0].set_ylabel("platen force (N)")
        ax[0].legend()
        pairs = [(s, at(ref, s + 1)) for s in ms]
        pairs = [(s, e) for s, e in pairs if e is not None and e[0] > 0]
        ax[1].semilogy([s for s, _ in pairs], [abs(mine[s][0] / e[0] - 1) + 1e-12 for s, e in pairs],
                       label="Basalt vs ESyS")
        if pert:
            ax[1].semilogy(ps, [abs(pert[s][0] / ref[s][0] - 1) + 1e-12 if s in ref and ref[s][0] > 0 else None
                                for s in ps], ":", label="ESyS perturbed vs ESyS")
        if args.basalt_perturbed:
            bp = basalt_series(args.basalt_perturbed)
            qs = [s for s in ms if s in bp and mine[s][0] > 0]
            ax[1].semilogy(qs, [abs(bp[s][0] / mine[s][0] - 1) + 1e-12 for s in qs], ":",
                           label="Basalt, one particle moved by 1e-12, vs Basalt")
        ax[1].set_ylabel("relative difference of F")
        ax[1].set_xlabel("step")
        ax[1].legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")
    if not ok:
        print("FAIL")
        return 1
    print("PASS" if complete else "PASS so far (the reference stops before its peak)")
    return 0 if complete else 2


if __name__ == "__main__":
    sys.exit(main())
