#!/usr/bin/python3
"""Two-sphere ESyS-Particle 2.3.5 runs of a BrittleBeam bond (RotBond), as reference data for Basalt's
rot_bond (tests/solver/test_rot_bond.cpp, RotBondEsys; docs/reference-runs.md, "Rotational bonds").

    /usr/bin/python3 tools/esys/probe_rotbond.py [--workdir DIR] [--case NAME] [--output docs/data/esys-rotbond]

Each case is one `mpirun -np 2 esysparticle` run (1 worker) of two RotSpheres joined by
BrittleBeamPrms(youngsModulus=1000, poissonsRatio=0.25, cohesion, tanAngle=1, meanR_scaling=True, truncated=1,
beta1=1, beta2=1), started with the velocities and angular velocities of the case; the state after every step
is read back from ESyS's checkpoint files and written as CSV (step,id,x,y,z,vx,vy,vz,qw,qx,qy,qz,wx,wy,wz).
Cases: a gap (initial distance > r1 + r2: the rest length is r1 + r2, the stiffness from the distance),
stretch, shear, twist, bend, a general motion, and a tension break (the step of the break shows when the
breaking force stops acting). Exit 3 if ESyS is missing.
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
E, NU, TAN = 1000.0, 0.25, 1.0
R1, R2 = 0.5, 0.4

# name: (distance, direction of the bond, v2, w2, w1, cohesion, steps)
CASES = {
    "gap": (0.95, (1, 0, 0), (0, 0, 0), (0, 0, 0), (0, 0, 0), 1e9, 300),
    "stretch": (0.9, (1, 0, 0), (0.05, 0, 0), (0, 0, 0), (0, 0, 0), 1e9, 300),
    "shear": (0.9, (1, 0, 0), (0, 0.05, 0), (0, 0, 0), (0, 0, 0), 1e9, 300),
    "twist": (0.9, (1, 0, 0), (0, 0, 0), (0.5, 0, 0), (0, 0, 0), 1e9, 300),
    "bend": (0.9, (1, 0, 0), (0, 0, 0), (0, 0, 0.5), (0, 0, 0), 1e9, 300),
    "general": (0.92, (1, 2, -0.5), (0.02, -0.03, 0.01), (0.3, -0.2, 0.4), (-0.1, 0.25, 0.05), 1e9, 400),
    "break": (0.9, (1, 0, 0), (2.0, 0, 0), (0, 0, 0), (0, 0, 0), 5.0, 60),
}


def geometry(case):
    d, e, v2, w2, w1, coh, steps = CASES[case]
    n = math.sqrt(sum(c * c for c in e))
    x2 = [d * c / n for c in e]
    m1, m2 = 4.0 / 3.0 * math.pi * R1**3, 4.0 / 3.0 * math.pi * R2**3
    return [(1, [0.0, 0.0, 0.0], R1, m1, (0, 0, 0), w1), (2, x2, R2, m2, v2, w2)], coh, steps


def run_esys(case, workdir):
    from esys.lsm import RotSphere, BrittleBeamPrms, CheckPointPrms
    from esys.lsm.util import Vec3
    from esys.lsm.geometry import TaggedIdConnection
    parts, coh, steps = geometry(case)
    os.chdir(workdir)
    sim = bt.esys_simulation([1, 1, 1], "RotSphere", 2.5, 0.2, (-20, -20, -20), (20, 20, 20), dt=DT)
    for (pid, x, r, m, v, w) in parts:
        sim.createParticle(RotSphere(id=pid, posn=Vec3(*x), radius=r, mass=m))
    sim.createConnections([TaggedIdConnection(1, 2, 0)])
    sim.createInteractionGroup(BrittleBeamPrms(name="bonds", youngsModulus=E, poissonsRatio=NU, cohesion=coh,
                                               tanAngle=TAN, tag=0, meanR_scaling=True, truncated=1.0, beta1=1.0,
                                               beta2=1.0))
    for (pid, x, r, m, v, w) in parts:
        if any(v):
            sim.setParticleVelocity(pid, Vec3(*v))
        if any(w):
            sim.setParticleAngularVelocity(pid, Vec3(*w))
    sim.createCheckPointer(CheckPointPrms(fileNamePrefix="cp", beginTimeStep=0, endTimeStep=steps, timeStepIncr=1))
    sim.setNumTimeSteps(steps)
    for _ in range(steps):
        sim.runTimeStep()
    sim.exit()


def read_state(workdir, step):
    rows, _ = bt.read_esys_checkpoint(os.path.join(workdir, "cp"), step)
    return {pid: v[0:3] + v[13:16] + v[22:26] + v[26:29] for pid, v in rows.items()}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--case", choices=list(CASES))
    p.add_argument("--workdir", default="out/esys_probe_rotbond")
    p.add_argument("--output", default="docs/data/esys-rotbond")
    args = p.parse_args()
    if bt.esys_child():
        run_esys(args.case, args.workdir)
        return 0
    if bt.esys_missing():
        print("ESyS-Particle is not available (esysparticle, mpirun). Nothing was run.", file=sys.stderr)
        return 3
    env = bt.esys_env()
    os.makedirs(args.output, exist_ok=True)
    failures = 0
    for case in ([args.case] if args.case else list(CASES)):
        workdir = os.path.abspath(os.path.join(args.workdir, case))
        shutil.rmtree(workdir, ignore_errors=True)
        os.makedirs(workdir)
        rc = subprocess.call(bt.esys_command(__file__, 2, ["--case", case,
                              "--workdir", workdir]), env=env, cwd=workdir, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
        if rc != 0:
            print(f"{case}: FAIL esysparticle exited with {rc}")
            failures += 1
            continue
        steps = geometry(case)[2]
        path = os.path.join(args.output, f"{case}.csv")
        with open(path, "w") as out:
            out.write("step,id,x,y,z,vx,vy,vz,qw,qx,qy,qz,wx,wy,wz\n")
            for step in range(steps + 1):
                for pid, v in sorted(read_state(workdir, step).items()):
                    out.write(f"{step},{pid}," + ",".join(f"{a:.9g}" for a in v) + "\n")
        print(f"{case}: {steps} steps -> {path}")
    return 1 if failures else 0


if __name__ == "__main__":
    if bt.esys_child():
        main()  # inside esysparticle: sys.exit would skip MPI_Finalize
    else:
        sys.exit(main())
