#!/usr/bin/env python3
"""Error and speed of basalt-run's presets (docs/stability.md, "Presets") on one scene + geometry.

    tools/studies/preset_error.py --build build --scene scenes/wave.toml \\
        --geometry $BASALT_REFERENCE_DIR/cube1.geo [--time 2.0] [--np 1]

Runs a reference (double, run.dt_fraction = 0.01) and each preset for the same simulated time, saving
the kinetic energy every step, and prints per preset: dt, steps, the L2 and max relative error of
the kinetic-energy curve against the reference (linearly interpolated at the preset's times, over
the times where the reference KE exceeds 1 % of its maximum), and the throughput basalt-run reports.
"""
import argparse
import math
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

PRESETS = {"fast": ("float", 0.5), "balanced": ("double", 0.25), "reference": ("double", 0.05)}


def basalt_run(args, work, tag, extra, steps):
    out = os.path.join(work, tag)
    cmd = bt.basalt_run_command(bt.binary("basalt-run", build=args.build), args.scene, "--geometry", args.geometry,
                                "--steps", steps, "--output", out, "--quiet", "--fields-every", "1", *extra,
                                np=args.np, launcher="mpiexec", flag="-n")
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{p.stderr}")
    cols = bt.read_fields(out)
    x = bt.parse_run(p.stdout)
    return (cols["time"], cols["kinetic_energy"], x["particle_steps_per_s"] / 1e6 if "particle_steps_per_s" in x
            else float("nan"), x.get("critical_step"))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--scene", default="scenes/wave.toml")
    ap.add_argument("--geometry", required=True)
    ap.add_argument("--time", type=float, default=2.0, help="simulated time (scene units)")
    ap.add_argument("--np", type=int, default=1)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="basalt-presets-") as work:
        _, _, _, crit = basalt_run(args, work, "probe", [], 0)
        ref_dt = 0.01 * crit
        # The reference: double at dt_fraction 0.01 (no preset has it): a scene copy with dt_fraction.
        with open(args.scene) as f:
            text = f.read()
        text = re.sub(r"(?m)^\s*dt(_fraction)?\s*=.*$", "dt_fraction = 0.01", text, count=1)
        ref_scene = os.path.join(work, "reference.toml")
        with open(ref_scene, "w") as f:
            f.write(text)
        rargs = argparse.Namespace(**{**vars(args), "scene": ref_scene})
        rt, rke, rspeed, _ = basalt_run(rargs, work, "ref", ["--precision", "double"],
                                        int(math.ceil(args.time / ref_dt)))
        peak = max(rke)
        print(f"scene {args.scene}, geometry {os.path.basename(args.geometry)}, {args.time} time units, "
              f"np {args.np}; critical step {crit:.6g}; reference double dt_fraction 0.01 "
              f"({len(rt)} steps, {rspeed} M particle-steps/s)")
        print("| preset | precision | dt_fraction | steps | KE L2 rel. error | KE max rel. error | M particle-steps/s |")
        print("| --- | --- | --- | --- | --- | --- | --- |")
        for name, (prec, frac) in PRESETS.items():
            steps = int(math.ceil(args.time / (frac * crit)))
            t, ke, speed, _ = basalt_run(args, work, name, ["--preset", name], steps)
            num = den = worst = 0.0
            for x, k in zip(t, ke):
                r = bt.interp(rt, rke, x)
                if r < 0.01 * peak:
                    continue
                num += (k - r) ** 2
                den += r * r
                worst = max(worst, abs(k - r) / r)
            print(f"| {name} | {prec} | {frac} | {steps} | {math.sqrt(num / den):.3g} | {worst:.3g} | {speed} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
