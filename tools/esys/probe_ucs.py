#!/usr/bin/python3
"""Measures the ESyS-Particle 2.3.5 conventions of the rot_compress test that tools/esys/probe_rotbond.py and
probe_granular.py do not: when a broken BrittleBeam pair gets its FrictionPrms interaction, FrictionPrms's
stiffnesses, and where the tutorial's WallLoaderRunnable (a pre-time-step runnable) puts the wall.

    /usr/bin/python3 tools/esys/probe_ucs.py [--workdir DIR] [--case NAME]

As tools/esys/probe_walls.py: each case is a separate `mpirun -np 2 esysparticle` run (1 worker), the state
after every step read back from ESyS's checkpoint files; every check prints the measured number next to the
rule it tests and fails (exit 1) if they disagree. Exit 3 if ESyS is missing.
Source read: pis/pi_storage_ed.hpp (ParallelInteractionStorage_ED::update: without a neighbour-table rebuild
only pairs of "flagged" particles are added), Parallel/SubLattice.hpp (updateInteractions, checkNeighbors:
rebuild when a particle moved more than verletDist/2), Model/RotFricInteraction.cpp (FrictionPrms).
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
E, NU = 1000.0, 0.25
R1, R2 = 0.5, 0.4
HEAVY = 1.0e6  # mass of the spheres that must not move: the bond and contact forces barely accelerate them
VERLET = 0.2   # rebuild when a particle moved more than 0.1
STEPS = 160

CASES = {
    "break_contact": "heavy bonded pair overlapping by 0.01 (BrittleBeam c = 1, FrictionPrms excluded against "
                     "the bond), twisted at 1 rad/ms until the bond breaks in torsion; nothing moves far enough "
                     "for a neighbour-table rebuild",
    "friction_prms": "unbonded pair overlapping by 0.01 with a relative tangential velocity 0.1: "
                     "FrictionPrms(E=1000, nu=0.25) stiffnesses",
    "wall_loader": "a heavy sphere touching a wall moved by WallLoaderRunnable(V dt = 0.001, rampTime 4), "
                   "pre-time-step",
}


def run_case(case, workdir):
    from esys.lsm import (RotSphere, BrittleBeamPrms, FrictionPrms, NRotElasticWallPrms, CheckPointPrms,
                          Runnable)
    from esys.lsm.util import Vec3
    from esys.lsm.geometry import TaggedIdConnection

    os.chdir(workdir)
    sim = bt.esys_simulation([1, 1, 1], "RotSphere", 2.5, VERLET, (-20, -20, -20), (20, 20, 20), dt=DT)
    steps = STEPS
    if case.startswith("break"):
        sim.createParticle(RotSphere(id=1, posn=Vec3(0, 0, 0), radius=R1, mass=HEAVY))
        sim.createParticle(RotSphere(id=2, posn=Vec3(0.89, 0, 0), radius=R2, mass=HEAVY))
        sim.createConnections([TaggedIdConnection(1, 2, 0)])
        sim.createInteractionGroup(BrittleBeamPrms(name="bonds", youngsModulus=E, poissonsRatio=NU, cohesion=1.0,
                                                   tanAngle=1.0, tag=0, meanR_scaling=True, truncated=1.0,
                                                   beta1=1.0, beta2=1.0))
        sim.createInteractionGroup(FrictionPrms(name="friction", youngsModulus=E, poissonsRatio=NU, dynamicMu=0.4,
                                                staticMu=0.6))
        sim.createExclusion(interactionName1="bonds", interactionName2="friction")
        sim.setParticleAngularVelocity(2, Vec3(1.0, 0, 0))
    elif case == "friction_prms":
        sim.createParticle(RotSphere(id=1, posn=Vec3(0, 0, 0), radius=R1, mass=HEAVY))
        sim.createParticle(RotSphere(id=2, posn=Vec3(0.89, 0, 0), radius=R2, mass=HEAVY))
        sim.createInteractionGroup(FrictionPrms(name="friction", youngsModulus=E, poissonsRatio=NU, dynamicMu=0.4,
                                                staticMu=0.6))
        sim.setParticleVelocity(2, Vec3(0, 0.1, 0))
        steps = 3
    elif case == "wall_loader":
        sim.createParticle(RotSphere(id=1, posn=Vec3(0, 0, 0.5), radius=0.5, mass=HEAVY))
        sim.createWall(name="w", posn=Vec3(0, 0, 0), normal=Vec3(0, 0, 1))
        sim.createInteractionGroup(NRotElasticWallPrms(name="wr", wallName="w", normalK=E))

        class WallLoaderRunnable(Runnable):  # the tutorial's WallLoader.py, startTime 0
            def __init__(self):
                Runnable.__init__(self)
                self.nt = 0

            def run(self):
                f = float(self.nt) / 4.0 if self.nt < 4 else 1.0
                sim.moveWallBy("w", Vec3(0, 0, f * 1.0 * DT))
                self.nt += 1

        loader = WallLoaderRunnable()
        sim.addPreTimeStepRunnable(loader)
        steps = 6
    sim.createCheckPointer(CheckPointPrms(fileNamePrefix="cp", beginTimeStep=0, endTimeStep=steps, timeStepIncr=1))
    sim.setNumTimeSteps(steps)
    for _ in range(steps):
        sim.runTimeStep()
    sim.exit()


def read_state(workdir, step):
    rows, _ = bt.read_esys_checkpoint(os.path.join(workdir, "cp"), step)
    return {pid: {"x": v[0:3], "v": v[13:16], "f": v[16:19]} for pid, v in rows.items()}


class Checker:
    def __init__(self):
        self.failures = 0

    def close(self, label, measured, expected, rtol=1e-6, atol=1e-9):
        ok = abs(measured - expected) <= max(rtol * abs(expected), atol)
        self.failures += not ok
        print(f"  {'ok  ' if ok else 'FAIL'} {label}: measured {measured:.9g}, expected {expected:.9g}")
        return ok


def bond_break_step(s):
    """The last step the twisted bond acts: the first n after which particle 1's force jumps (the spheres
    barely move, so the bond's force changes by ~1e-7 relative per step; the contact's differs by 1 %)."""
    for n in range(1, len(s) - 1):
        f, g = s[n][1]["f"][0], s[n + 1][1]["f"][0]
        if abs(g - f) > 1e-3 * abs(f):
            return n
    return None


def check(case, workdir, c):
    if case.startswith("break"):
        s = [read_state(workdir, k) for k in range(STEPS + 1)]
        b = bond_break_step(s)
        if b is None:
            c.failures += 1
            print("  FAIL the bond did not break")
            return
        # Bond force on 1 at step 1: kn (L - r0) along +x (the pair is compressed: pushes 1 to -x).
        L = 0.89
        R = L / 2
        kn = math.pi * E * R * R / L
        c.close("bond normal force on 1 at step 1 (kn (d - (r1 + r2)), kn from the initial distance)",
                s[1][1]["f"][0], kn * (L - 0.9), rtol=1e-5)
        print(f"  the bond's last step: {b} (torsion: 1 rad/ms relative spin)")
        k = math.pi * E * (R1 + R2) / 4  # FrictionPrms: pi E, scaled by (r1 + r2)/4
        d = abs(s[b][2]["x"][0] - s[b][1]["x"][0])
        c.close(f"force on 1 at step {b + 1}, the step after the break: the friction contact -k (r1 + r2 - d), "
                "k = pi E (r1 + r2)/4, d after step b", s[b + 1][1]["f"][0], -k * (R1 + R2 - d), rtol=1e-6)
        worst = max(abs(s[n][1]["f"][0] / s[b + 1][1]["f"][0] - 1) for n in range(b + 1, STEPS + 1))
        c.close(f"the contact acts through step {STEPS} (largest relative change of the force on 1)", worst, 0.0,
                atol=1e-4)
        # The criterion on the loads of step n (ESyS's truncated Mohr-Coulomb, beta2 = 1), from the state after
        # step n - 1: torsion kt psi with psi = (n - 1) dt 1 rad/ms, normal force kn (d - (r1 + r2)) < 0.
        kt = math.pi * E / (2 * (1 + NU)) * R ** 4 / (2 * L)
        mt_max, fn_max = math.pi * 1.0 * R ** 3 / 2, math.pi * 1.0 * R * R

        def margin(n):
            dn = abs(s[n - 1][2]["x"][0] - s[n - 1][1]["x"][0])
            return kt * (n - 1) * DT / mt_max - (1 + kn * (0.9 - dn) / fn_max)

        print(f"  criterion (shear + normal - 1) on the loads of steps {b - 1}, {b}: {margin(b - 1):.4g}, "
              f"{margin(b):.4g} (first met in step {b}; its force still acts in that step)")
        ok = margin(b - 1) <= 0 < margin(b)
        c.failures += not ok
        print(f"  {'ok  ' if ok else 'FAIL'} the bond breaks in the step its loads first meet the criterion")
    elif case == "friction_prms":
        s = [read_state(workdir, k) for k in range(4)]
        k = math.pi * E * (R1 + R2) / 4
        ks = math.pi * E / (2 * (1 + NU)) * (R1 + R2) / 4
        c.close("normal force on 1 at step 1: -pi E (r1 + r2)/4 * overlap", s[1][1]["f"][0], -k * 0.01, rtol=1e-5)
        c.close("shear force on 1 at step 1: pi E/(2(1 + nu)) (r1 + r2)/4 * dt * 0.1", s[1][1]["f"][1],
                ks * DT * 0.1, rtol=1e-5)
    elif case == "wall_loader":
        s = [read_state(workdir, k) for k in range(7)]
        k = math.pi * 0.5 * E
        z = 0.0
        for n in range(1, 7):
            z += (min(n - 1, 4) / 4.0) * 1.0 * DT  # the move of call n-1, made before the forces of step n
            c.close(f"step {n}: wall force = pi r K z_w, z_w = V dt sum_(k<n) f_k = {z:.6g}", s[n][1]["f"][2],
                    k * (z + 0.5 - s[n - 1][1]["x"][2]), rtol=1e-5, atol=1e-9)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--case", choices=sorted(CASES))
    p.add_argument("--workdir", default="out/esys_probe_ucs")
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
