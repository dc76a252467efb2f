#!/usr/bin/python3
"""Runs the wave benchmark with ESyS-Particle's conventions (scenes/wave-esys.toml) on cube1.geo and
compares its kinetic-energy series with ESyS-Particle 2.3.5's (docs/data/esys_cube1_ekin.csv, made by
tools/esys/wave_benchmark.py on the reference branch).

    /usr/bin/python3 tools/compare_esys.py [--steps 2000] [--np 1] [--build build] [--plot docs/data/esys_compare.png]

Prints the largest relative deviation over the steps whose kinetic energy is non-negligible
(> 1e-3 of the series' maximum) and exits 1 when it exceeds --tolerance (1 %).
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

ROOT = bt.ROOT


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--steps", type=int, default=2000)
    p.add_argument("--np", type=int, default=1, help="MPI ranks for basalt-run")
    p.add_argument("--build", default=os.path.join(ROOT, "build"))
    p.add_argument("--geometry", default=os.path.join(ROOT, "tests", "data", "cube1.geo"))
    p.add_argument("--reference", default=None,
                   help="ESyS series (default docs/data/esys_cube1_ekin.csv, or _10000 for more than 2000 steps)")
    p.add_argument("--plot", default=os.path.join(ROOT, "docs", "data", "esys_compare.png"))
    p.add_argument("--tolerance", type=float, default=0.01)
    a = p.parse_args()
    ref_file = a.reference or os.path.join(
        ROOT, "docs", "data", "esys_cube1_ekin.csv" if a.steps <= 2000 else "esys_cube1_ekin_10000.csv")
    if not os.path.exists(a.geometry):
        sys.exit(f"compare_esys: geometry {a.geometry} not found (--geometry)")
    exe = bt.binary("basalt-run", build=a.build)
    if not os.access(exe, os.X_OK):
        sys.exit(f"compare_esys: {exe} not built (cmake --build {a.build} --target basalt-run)")
    with tempfile.TemporaryDirectory() as out:
        cmd = bt.basalt_run_command(exe, os.path.join(ROOT, "scenes", "wave-esys.toml"), "--geometry", a.geometry,
                                    "--steps", a.steps, "--output", out, "--quiet", np=a.np)
        subprocess.run(cmd, check=True)
        ours = bt.read_fields(out)
    ref = np.loadtxt(ref_file, delimiter=",", skiprows=1, ndmin=2)
    ref = {int(s): ke for s, _, ke in ref}
    steps = np.array(ours["step"])
    missing = [s for s in steps if s not in ref]
    if missing:
        sys.exit(f"compare_esys: the reference {ref_file} lacks steps {missing[0]}..")
    r = np.array([ref[s] for s in steps])
    b = np.array(ours["kinetic_energy"])
    sig = r > 1e-3 * r.max()
    rel = np.abs(b - r)[sig] / r[sig]
    worst = rel.max()
    at = steps[sig][rel.argmax()]
    print(f"steps 1..{a.steps}: max relative KE deviation {worst:.3g} at step {at} "
          f"(over {sig.sum()} steps with KE > 1e-3 of max); median {np.median(rel):.3g}; "
          f"final KE Basalt {b[-1]:.6g}, ESyS {r[-1]:.6g}")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, gridspec_kw={"height_ratios": [3, 1]})
        ax1.plot(steps, r, label="ESyS-Particle 2.3.5", lw=2.5, color="0.6")
        ax1.plot(steps, b, label="Basalt (scenes/wave-esys.toml)", lw=1, color="C3")
        ax1.set_ylabel("kinetic energy (N mm)")
        ax1.legend()
        ax1.set_title("Wave benchmark on cube1.geo (8,948 particles)")
        ax2.semilogy(steps[sig], np.maximum(rel, 1e-12), color="C0", lw=0.8)
        ax2.set_ylabel("relative difference")
        ax2.set_xlabel("step")
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)
        print(f"plot: {a.plot}")
    return 0 if worst <= a.tolerance else 1


if __name__ == "__main__":
    sys.exit(main())
