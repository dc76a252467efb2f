#!/usr/bin/env python3
"""Measures the largest stable time step of a scene + geometry by bisection with basalt-run.

    tools/studies/stability_limit.py --build build --scene scenes/wave.toml \\
        --geometry $BASALT_REFERENCE_DIR/cube1.geo [--steps 2000] [--np 1] [--precision double]

Each trial runs the scene with run.dt replaced (and --force-dt) for --steps steps, saving the kinetic
energy every step. A trial is stable when basalt-run succeeds and the largest kinetic energy stays
below --growth x that of a run at a quarter of the estimated critical step; unstable runs are stopped
by the blow-up check or the energy guard (exit status 1) or show the growth. The bisection starts from
[0.5, 1.5] x basalt-run's estimate (the "critical step:" line it prints) and stops when the bracket is
narrower than --rtol. Prints the estimate, the measured limit and their ratio (docs/stability.md).
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)


def scene_with_dt(text, dt):
    """The scene text with [run] dt (or dt_fraction) replaced by dt = <dt>."""
    out, section, done = [], None, False
    for line in text.splitlines():
        m = re.match(r"\s*\[([^\]]+)\]", line)
        if m and not line.strip().startswith("[["):
            section = m.group(1).strip()
        if section == "run" and re.match(r"\s*(dt|dt_fraction)\s*=", line):
            if not done:
                out.append(f"dt = {dt!r}")
                done = True
            continue
        out.append(line)
    if not done:
        raise SystemExit("the scene has no run.dt or run.dt_fraction")
    return "\n".join(out) + "\n"


def run(args, dt, work, tag):
    scene = os.path.join(work, f"scene_{tag}.toml")
    with open(args.scene) as f:
        text = scene_with_dt(f.read(), dt)
    with open(scene, "w") as f:
        f.write(text)
    out = os.path.join(work, f"out_{tag}")
    cmd = bt.basalt_run_command(bt.binary("basalt-run", build=args.build), scene, "--geometry", args.geometry,
                                "--steps", args.steps, "--output", out, "--quiet", "--force-dt", "--fields-every", "1",
                                "--precision", args.precision, np=args.np, launcher="mpiexec", flag="-n")
    p = subprocess.run(cmd, capture_output=True, text=True)
    estimate = bt.parse_run(p.stdout).get("critical_step")
    ke = []
    fields = os.path.join(out, "fields.csv")
    if os.path.exists(fields):
        cols = bt.read_fields(fields)
        ke = cols["kinetic_energy"] if "kinetic_energy" in cols else cols[list(cols)[2]]
    err = p.stderr.strip().splitlines()[-1] if p.returncode != 0 and p.stderr.strip() else ""
    return p.returncode, estimate, ke, err


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--scene", default="scenes/wave.toml")
    ap.add_argument("--geometry", required=True)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--np", type=int, default=1)
    ap.add_argument("--precision", default="double", choices=["double", "float"])
    ap.add_argument("--growth", type=float, default=1.5,
                    help="unstable when the largest KE exceeds this x the reference run's")
    ap.add_argument("--rtol", type=float, default=2e-3, help="relative width of the final bracket")
    args = ap.parse_args()

    with tempfile.TemporaryDirectory(prefix="basalt-stability-") as work:
        # The estimate: a run of 0 steps prints it.
        code, estimate, _, err = run(argparse.Namespace(**{**vars(args), "steps": 0}), 1e-9, work, "probe")
        if estimate is None:
            raise SystemExit(f"basalt-run printed no critical step ({err})")
        code, _, ke_ref, err = run(args, 0.25 * estimate, work, "ref")
        if code != 0:
            raise SystemExit(f"the reference run at 0.25 x the estimate failed: {err}")
        ke_max = max(ke_ref)

        def stable(dt, tag):
            code, _, ke, err = run(args, dt, work, tag)
            ok = code == 0 and all(k == k for k in ke) and max(ke) <= args.growth * ke_max
            why = "ok" if ok else (err if code != 0 else f"max KE {max(ke):.4g} > {args.growth} x {ke_max:.4g}")
            print(f"  dt = {dt:.6g} ({dt / estimate:.4f} x estimate): {'stable' if ok else 'unstable'} ({why})",
                  flush=True)
            return ok

        lo, hi = 0.5 * estimate, 1.5 * estimate
        if not stable(lo, "lo"):
            raise SystemExit("unstable at 0.5 x the estimate: the bracket does not hold")
        if stable(hi, "hi"):
            raise SystemExit("stable at 1.5 x the estimate: the bracket does not hold")
        k = 0
        while (hi - lo) / lo > args.rtol:
            mid = 0.5 * (lo + hi)
            if stable(mid, f"b{k}"):
                lo = mid
            else:
                hi = mid
            k += 1
    limit = 0.5 * (lo + hi)
    print(f"scene {args.scene}, geometry {os.path.basename(args.geometry)}, {args.steps} steps, np {args.np}, "
          f"{args.precision}")
    print(f"estimated critical step (power iterations): {estimate:.6g}")
    print(f"measured stability limit: {limit:.6g} (bracket [{lo:.6g}, {hi:.6g}])")
    print(f"estimate / measured: {estimate / limit:.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
