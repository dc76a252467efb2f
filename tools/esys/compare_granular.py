#!/usr/bin/python3
"""Compares Basalt's run of scenes/granular-esys.toml with ESyS-Particle's reference run
(docs/reference-runs.md, "Granular reference run"; docs/verification.md, "Granular column collapse").

    basalt-run scenes/granular-esys.toml --output out/granular-esys
    /usr/bin/python3 tools/esys/compare_granular.py out/granular-esys [--plot docs/img/granular_esys_ke.png]
    (or --basalt-run build/bin/basalt-run to run the scene into that folder first: the ctest solver_esys_granular)

Checks (exit 1 when one fails):
  - kinetic energy (translational + rotational, ESyS's e_kin) within 1 % of ESyS's base run at every saved step
    where it is above 1 % of its peak, both before the chaos window ends (the step where ESyS's base and
    perturbed runs first differ, found from their series) and over the whole run;
  - the deposit after the last step: centre of mass (x, z) and the 95th percentile of x (the front) within 2 % of
    ESyS's (tools/esys/deposit_metrics.py, the same arithmetic for both codes).
Also prints ESyS against its own perturbed run, the yardstick for what chaos alone does.
"""

import argparse
import csv
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)
import deposit_metrics  # noqa: E402

DATA = os.path.join(HERE, "..", "..", "docs", "data", "esys-granular")


def series(path, column="kinetic_energy"):
    with open(path, newline="") as f:
        return {int(r["step"]): float(r[column]) for r in csv.DictReader(f) if r.get(column, "") != ""}


def worst(ref, other, last_step=None):
    peak = max(ref.values())
    w, at = 0.0, None
    for s, v in ref.items():
        if s not in other or (last_step is not None and s > last_step) or v < 0.01 * peak:
            continue
        d = abs(other[s] - v) / v
        if d > w:
            w, at = d, s
    return w, at


def positions_csv(run_dir, out_path):
    last = bt.last_checkpoint(run_dir)
    if not last:
        raise SystemExit(f"error: {run_dir}: no checkpoint (the scene writes one at the last step)")
    pos, rad, ids = bt.read_h5(last, "/particles/position", "/particles/radius", "/particles/id")
    with open(out_path, "w") as o:
        o.write("id,x,y,z,r\n")
        for i, p, r in zip(ids, pos, rad):
            o.write(f"{i},{p[0]!r},{p[1]!r},{p[2]!r},{r!r}\n")
    return last


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--plot", default="")
    ap.add_argument("--basalt-run", default="", help="run scenes/granular-esys.toml with this binary into RUN_DIR first")
    args = ap.parse_args()
    if args.basalt_run:
        import subprocess
        scene = os.path.join(HERE, "..", "..", "scenes", "granular-esys.toml")
        cmd = [args.basalt_run, scene, "--geometry", os.path.join(DATA, "column.geo"), "--output", args.run_dir,
               "--quiet"]
        if subprocess.call(cmd) != 0:
            print("FAIL: " + " ".join(cmd) + " exited non-zero")
            return 1
    base = series(os.path.join(DATA, "ekin_base.csv"))
    pert = series(os.path.join(DATA, "ekin_perturbed.csv"))
    mine = series(os.path.join(args.run_dir, "fields.csv"))
    chaos = min((s for s in base if s in pert and base[s] != pert[s]), default=max(base))
    ok = True
    print(f"chaos window: ESyS base and perturbed runs first differ at step {chaos}")
    for label, lim in (("before the chaos window", chaos), ("whole run", None)):
        w, at = worst(base, mine, lim)
        we, ate = worst(base, pert, lim)
        print(f"KE {label}: Basalt vs ESyS max {w:.3e} (step {at}); ESyS perturbed vs ESyS max {we:.3e} (step {ate})")
        ok = ok and w < 0.01
    ckpt = positions_csv(args.run_dir, os.path.join(args.run_dir, "positions.csv"))
    b = deposit_metrics.metrics(os.path.join(DATA, "positions_base.csv"))
    p = deposit_metrics.metrics(os.path.join(DATA, "positions_perturbed.csv"))
    m = deposit_metrics.metrics(os.path.join(args.run_dir, "positions.csv"))
    print(f"deposit from {ckpt}:")
    print("| | ESyS | ESyS perturbed | Basalt | Basalt vs ESyS |")
    print("| --- | --- | --- | --- | --- |")
    for key in ("com_x", "com_y", "com_z", "x_p95", "x_max"):
        rel = abs(m[key] - b[key]) / abs(b[key])
        print(f"| {key} | {b[key]:.4f} | {p[key]:.4f} | {m[key]:.4f} | {100 * rel:.2f} % |")
        if key in ("com_x", "com_z", "x_p95"):
            ok = ok and rel < 0.02
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
        steps = sorted(s for s in base if s in mine)
        ax[0].plot(steps, [base[s] for s in steps], label="ESyS-Particle 2.3.5")
        ax[0].plot(steps, [mine[s] for s in steps], "--", label="Basalt")
        ax[0].set_ylabel("kinetic energy")
        ax[0].legend()
        ax[1].semilogy(steps, [abs(mine[s] - base[s]) / max(base[s], 1e-300) for s in steps], label="Basalt vs ESyS")
        ps = sorted(s for s in base if s in pert)
        ax[1].semilogy(ps, [abs(pert[s] - base[s]) / max(base[s], 1e-300) + 1e-12 for s in ps],
                       label="ESyS perturbed 1e-9 vs ESyS")
        ax[1].axvline(chaos, color="grey", lw=0.8)
        ax[1].set_ylabel("relative difference")
        ax[1].set_xlabel("step")
        ax[1].legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")
    print("PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
