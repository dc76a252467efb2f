#!/usr/bin/python3
"""Measures ESyS-Particle 2.3.5's conventions on one- and two-particle systems.

    /usr/bin/python3 tools/esys/probe_conventions.py [--workdir DIR]

Each case is a separate `mpirun -np 2 esysparticle` run (1 worker) of this script with --case;
the state after steps 0..3 is read back from ESyS's own checkpoint files (getParticleList and
getParticlePosn crash or return zeros in the Debian 2.3.5 build). Every check prints the measured
number next to the formula it tests and fails (exit 1) if they disagree.

Checkpoint particle line (observed): x y z r id tag mass x0 y0 z0 xold yold zold vx vy vz fx fy fz ...
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

# name -> description; geometry built in run_case
CASES = {
    "bond_geo": "two particles r=0.5,0.3 read from a .geo at distance 0.9, bonded (NRotBond, scaling=False)",
    "bond_compressed": "bonded pair created in Python at distance 0.7 (r1+r2 = 0.8)",
    "elastic": "unbonded pair at distance 0.7 (overlap 0.1), NRotElastic scaling=False",
    "wall_r05": "particle r=0.5 at z=0.4 above a wall z=0 (overlap 0.1), NRotElasticWall",
    "wall_r025": "particle r=0.25 at z=0.2 (overlap 0.05), NRotElasticWall",
    "integrator": "particle r=0.5, m=1, v0=0.3 at z=0.4 on the wall; e_kin SUM saver",
    "break_0.124": "bonded pair at distance 0.9 (strain (0.9-0.8)/0.8 = 0.125), breakDistance 0.124",
    "break_0.126": "same, breakDistance 0.126",
    "exclusion_on": "bonded pair at 0.7 with NRotBond and NRotElastic groups, createExclusion(bond, elastic)",
    "exclusion_off": "same without the exclusion",
    "runnable": "post-time-step runnable moves the wall 0.01 each step; wall position saver",
}


def run_case(case, workdir):
    from esys.lsm import (NRotSphere, NRotBondPrms, NRotElasticPrms, NRotElasticWallPrms,
                          ParticleScalarFieldSaverPrms, WallVectorFieldSaverPrms, CheckPointPrms, Runnable)
    from esys.lsm.util import Vec3
    from esys.lsm.geometry import TaggedIdConnection

    os.chdir(workdir)
    sim = bt.esys_simulation([1, 1, 1], "NRotSphere", 2.5, 0.2, (-20, -20, -20), (20, 20, 20), dt=DT)

    def pair(distance, bonded, break_distance=1e9):
        sim.createParticle(NRotSphere(id=0, posn=Vec3(0, 0, 0), radius=0.5, mass=1.0))
        sim.createParticle(NRotSphere(id=1, posn=Vec3(distance, 0, 0), radius=0.3, mass=1.0))
        if bonded:
            sim.createConnections([TaggedIdConnection(0, 1, 0)])
            sim.createInteractionGroup(NRotBondPrms(name="b", normalK=K, breakDistance=break_distance, tag=0,
                                                    scaling=False))

    def on_wall(r, z, v0=0.0):
        sim.createParticle(NRotSphere(id=0, posn=Vec3(0, 0, z), radius=r, mass=1.0))
        if v0:
            sim.setParticleVelocity(0, Vec3(0, 0, v0))
        sim.createWall(name="base", posn=Vec3(0, 0, 0), normal=Vec3(0, 0, 1))
        sim.createInteractionGroup(NRotElasticWallPrms(name="w", wallName="base", normalK=K))

    if case == "bond_geo":
        with open("two.geo", "w") as f:
            f.write("LSMGeometry 1.2\nBoundingBox -5 -5 -5 5 5 5\nPeriodicBoundaries 0 0 0\nDimension 3D\n"
                    "BeginParticles\nSimple\n2\n0 0 0 0.5 0 1\n0.9 0 0 0.3 1 1\nEndParticles\n"
                    "BeginConnect\n1\n0 1 0\nEndConnect\n")
        sim.readGeometry("two.geo")
        sim.createInteractionGroup(NRotBondPrms(name="b", normalK=K, breakDistance=1e9, tag=0, scaling=False))
    elif case == "bond_compressed":
        pair(0.7, True)
    elif case == "elastic":
        pair(0.7, False)
        sim.createInteractionGroup(NRotElasticPrms(name="e", normalK=K, scaling=False))
    elif case == "wall_r05":
        on_wall(0.5, 0.4)
    elif case == "wall_r025":
        on_wall(0.25, 0.2)
    elif case == "integrator":
        on_wall(0.5, 0.4, v0=0.3)
        sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="ekin.dat", fileFormat="SUM",
                                                          beginTimeStep=0, endTimeStep=3, timeStepIncr=1))
    elif case.startswith("exclusion_"):
        pair(0.7, True)
        sim.createInteractionGroup(NRotElasticPrms(name="e", normalK=K, scaling=False))
        if case == "exclusion_on":
            sim.createExclusion("b", "e")
    elif case.startswith("break_"):
        pair(0.9, True, float(case.split("_")[1]))
    elif case == "runnable":
        on_wall(0.5, 0.5)

        class Mover(Runnable):
            def __init__(self):
                Runnable.__init__(self)
                self.seen = []

            def run(self):
                self.seen.append(sim.getTimeStep())
                sim.moveWallBy("base", Vec3(0, 0, 0.01))

        mover = Mover()
        sim.addPostTimeStepRunnable(mover)
        sim.createFieldSaver(WallVectorFieldSaverPrms(wallName=["base"], fieldName="Position", fileName="wpos.dat",
                                                      fileFormat="RAW_SERIES", beginTimeStep=0, endTimeStep=3,
                                                      timeStepIncr=1))
    sim.createCheckPointer(CheckPointPrms(fileNamePrefix="cp", beginTimeStep=0, endTimeStep=3, timeStepIncr=1))
    sim.setNumTimeSteps(3)
    for _ in range(3):
        sim.runTimeStep()
    if case == "runnable":
        with open("runnable_steps.txt", "w") as f:
            f.write(" ".join(str(s) for s in mover.seen) + "\n")
    sim.exit()


def read_state(workdir, step):
    """Particles (by id) and bond count from ESyS's checkpoint after `step` steps."""
    rows, bonds = bt.read_esys_checkpoint(os.path.join(workdir, "cp"), step)
    parts = {pid: {"x": v[0:3], "r": v[3], "mass": v[6], "v": v[13:16], "f": v[16:19]} for pid, v in rows.items()}
    return parts, bonds


class Checker:
    def __init__(self):
        self.failures = 0

    def close(self, label, measured, expected, rtol=1e-6):
        ok = abs(measured - expected) <= rtol * max(abs(expected), 1e-12)
        self.failures += not ok
        print(f"  {'ok  ' if ok else 'FAIL'} {label}: measured {measured:.9g}, expected {expected:.9g}")


def check(case, workdir, c):
    s0, b0 = read_state(workdir, 0)
    s1, b1 = read_state(workdir, 1)
    s2, _ = read_state(workdir, 2)
    if case == "bond_geo":
        c.close("readGeometry mass r=0.5 = 4/3 pi r^3", s0[0]["mass"], 4 / 3 * math.pi * 0.5 ** 3)
        c.close("readGeometry mass r=0.3 = 4/3 pi r^3", s0[1]["mass"], 4 / 3 * math.pi * 0.3 ** 3)
        c.close("bond force step 1 = K (d - (r1+r2)) = 1000 (0.9-0.8)", s1[0]["f"][0], K * (0.9 - 0.8))
        print(f"  (rest length = initial distance would give 0; measured {s1[0]['f'][0]:.6g})")
    elif case == "bond_compressed":
        c.close("bond force step 1 = K (d - (r1+r2)) = 1000 (0.7-0.8)", s1[0]["f"][0], K * (0.7 - 0.8))
    elif case == "elastic":
        c.close("contact force step 1 = -K overlap", s1[0]["f"][0], -K * 0.1)
    elif case in ("wall_r05", "wall_r025"):
        r, z = (0.5, 0.4) if case == "wall_r05" else (0.25, 0.2)
        c.close(f"wall force step 1 = pi r K overlap (r={r})", s1[0]["f"][2], math.pi * r * K * (r - z))
        print(f"  (plain K overlap would give {K * (r - z):.6g})")
    elif case == "integrator":
        f1 = math.pi * 0.5 * K * 0.1
        v1 = 0.3 + f1 * DT
        x1 = 0.4 + v1 * DT
        c.close("v(1) = v(0) + F(x(0)) dt / m", s1[0]["v"][2], v1)
        c.close("x(1) = x(0) + v(1) dt  (symplectic Euler)", s1[0]["x"][2], x1)
        f2 = math.pi * 0.5 * K * (0.5 - x1)
        c.close("F saved at step 2 = F(x(1))", s2[0]["f"][2], f2)
        with open(os.path.join(workdir, "ekin.dat")) as f:
            ek = [float(l) for l in f if l.strip()]
        # the SUM saver prints 6 significant digits
        c.close("e_kin row 0 = m v(0)^2 / 2 (initial state)", ek[0], 0.5 * 0.3 ** 2, rtol=1e-5)
        c.close("e_kin row 1 = m v(1)^2 / 2 (velocity after the kick of step 1)", ek[1], 0.5 * v1 ** 2, rtol=1e-5)
        c.close("e_kin rows for steps 0..3", len(ek), 4)
    elif case.startswith("exclusion_"):
        both = case == "exclusion_off"
        c.close("force on a compressed bonded pair: bond only (-100) or bond + contact (-200)", s1[0]["f"][0],
                -200.0 if both else -100.0)
    elif case.startswith("break_"):
        bd = float(case.split("_")[1])
        s3, b3 = read_state(workdir, 3)
        expect_broken = (0.9 - 0.8) / 0.8 > bd
        c.close(f"bonds after 1 step with breakDistance {bd} (strain 0.125)", b1, 0 if expect_broken else 1)
        c.close("force at step 1 (0 if the bond broke before forces)", s1[0]["f"][0],
                0.0 if expect_broken else K * 0.1)
    elif case == "runnable":
        with open(os.path.join(workdir, "wpos.dat")) as f:
            wz = [float(l.split()[2]) for l in f if l.strip()]
        with open(os.path.join(workdir, "runnable_steps.txt")) as f:
            seen = f.read().split()
        print(f"  getTimeStep() seen inside the post-step runnable of steps 1,2,3: {' '.join(seen)}")
        print(f"  wall z saved at steps 0..3: {wz}")
        c.close("wall z saved at step 1 (runnable of step 1 already ran)", wz[1], 0.0, rtol=0)
        c.close("wall force in step 2 uses the wall moved after step 1: pi r K 0.01", s2[0]["f"][2],
                math.pi * 0.5 * K * 0.01)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--case", choices=sorted(CASES))
    p.add_argument("--workdir", default="esys_probe")
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
                              "--workdir", workdir]), env=env, cwd=workdir, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
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
