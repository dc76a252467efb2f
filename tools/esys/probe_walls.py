#!/usr/bin/python3
"""Measures ESyS-Particle 2.3.5's bonded wall (NRotBondedWall) on one particle and one wall.

    /usr/bin/python3 tools/esys/probe_walls.py [--workdir DIR]

As tools/esys/probe_conventions.py: each case is a separate `mpirun -np 2 esysparticle` run (1 worker),
the state after steps 0..3 read back from ESyS's checkpoint files; every check prints the measured
number next to the formula it tests and fails (exit 1) if they disagree. Source read:
Model/BWallInteraction.hpp (F = -k (u_p - u_w), k = 3.1415926536 r K), BWallInteractionGroup.hpp
(particles of the tag bonded, the others get CElasticWallInteraction with k = 3.141592654 r K).
"""

import argparse
import math
import os
import shutil
import subprocess
import sys

# tools/ (esysparticle's embedded interpreter does not add the script's folder either)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)
DT = 1e-3
K = 1000.0
R = 0.5
MOVE = (0.01, -0.004, 0.02)  # the wall's displacement after every step (post-time-step runnable)

CASES = {
    "bonded": "particle r=0.5 tag 2 at z=0.5 bonded to a wall z=0 that moves by (0.01, -0.004, 0.02) each step",
    "bonded_at_rest": "particle r=0.5 tag 2 at z=0.3 (overlapping) bonded to a fixed wall: no force at rest",
    "untagged": "particle r=0.5 tag 0 at z=0.4 (overlap 0.1) against the same bonded-wall group",
}


def run_case(case, workdir):
    from esys.lsm import NRotSphere, NRotBondedWallPrms, CheckPointPrms, Runnable
    from esys.lsm.util import Vec3

    os.chdir(workdir)
    sim = bt.esys_simulation([1, 1, 1], "NRotSphere", 2.5, 0.2, (-20, -20, -20), (20, 20, 20), dt=DT)
    z, tag = {"bonded": (0.5, 2), "bonded_at_rest": (0.3, 2), "untagged": (0.4, 0)}[case]
    particle = NRotSphere(id=0, posn=Vec3(0, 0, z), radius=R, mass=1.0)
    particle.setTag(tag)
    sim.createParticle(particle)
    sim.createWall(name="base", posn=Vec3(0, 0, 0), normal=Vec3(0, 0, 1))
    sim.createInteractionGroup(NRotBondedWallPrms(name="bw", wallName="base", normalK=K, particleTag=2))

    class Mover(Runnable):
        def __init__(self):
            Runnable.__init__(self)

        def run(self):
            sim.moveWallBy("base", Vec3(*MOVE))

    if case == "bonded":
        mover = Mover()
        sim.addPostTimeStepRunnable(mover)
    sim.createCheckPointer(CheckPointPrms(fileNamePrefix="cp", beginTimeStep=0, endTimeStep=3, timeStepIncr=1))
    sim.setNumTimeSteps(3)
    for _ in range(3):
        sim.runTimeStep()
    sim.exit()


def read_state(workdir, step):
    rows, _ = bt.read_esys_checkpoint(os.path.join(workdir, "cp"), step)
    return {pid: {"x": v[0:3], "x0": v[7:10], "v": v[13:16], "f": v[16:19]} for pid, v in rows.items()}


class Checker:
    def __init__(self):
        self.failures = 0

    def close(self, label, measured, expected, rtol=1e-6, atol=1e-12):
        ok = abs(measured - expected) <= max(rtol * abs(expected), atol)
        self.failures += not ok
        print(f"  {'ok  ' if ok else 'FAIL'} {label}: measured {measured:.9g}, expected {expected:.9g}")


def check(case, workdir, c):
    s = [read_state(workdir, k)[0] for k in range(4)]
    if case == "bonded":
        k = 3.1415926536 * R * K
        # Forces of step n use the particle's position after step n-1 and the wall moved by the runnables
        # of steps 1..n-1 (symplectic Euler; post-time-step runnables, probe_conventions.py "runnable").
        for n in (2, 3):
            xp = s[n - 1]["x"]
            for d, axis in enumerate("xyz"):
                u_p = xp[d] - s[0]["x"][d]
                u_w = (n - 1) * MOVE[d]
                c.close(f"step {n} F_{axis} = -pi r K (u_p - u_w), u_w = {u_w:g}", s[n]["f"][d], -k * (u_p - u_w))
        print(f"  (the full vector: the tangential components follow the wall too; plain K would give "
              f"{-K * ((s[1]['x'][0] - s[0]['x'][0]) - MOVE[0]):.6g} for F_x at step 2)")
    elif case == "bonded_at_rest":
        c.close("bonded particle overlapping a fixed wall: F_z at step 1 (rest = start, no repulsion)",
                s[1]["f"][2], 0.0, atol=1e-12)
    elif case == "untagged":
        c.close("untagged particle: elastic wall F_z = 3.141592654 r K overlap", s[1]["f"][2],
                3.141592654 * R * K * 0.1)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--case", choices=sorted(CASES))
    p.add_argument("--workdir", default="esys_probe_walls")
    args = p.parse_args()
    if bt.esys_child():
        run_case(args.case, args.workdir)
        return 0
    missing = bt.esys_missing()
    if missing:
        print(f"ESyS-Particle is not available: {', '.join(missing)} not on PATH. Nothing was run.", file=sys.stderr)
        return 3
    env = bt.esys_env()
    c = Checker()
    for case in ([args.case] if args.case else CASES):
        workdir = os.path.abspath(os.path.join(args.workdir, case))
        shutil.rmtree(workdir, ignore_errors=True)
        os.makedirs(workdir)
        print(f"{case}: {CASES[case]}", flush=True)
        rc = subprocess.call(bt.esys_command(__file__, 2, ["--case", case,
                              "--workdir", workdir]), env=env, cwd=workdir, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
        if rc != 0:
            print(f"  FAIL esysparticle exited with {rc}")
            c.failures += 1
            continue
        check(case, workdir, c)
    print(f"{c.failures} check(s) failed")
    return 1 if c.failures else 0


if __name__ == "__main__":
    if bt.esys_child():
        main()  # inside esysparticle: sys.exit would skip MPI_Finalize
    else:
        sys.exit(main())
