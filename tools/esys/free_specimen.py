#!/usr/bin/python3
"""ESyS-Particle 2.3.5 run of a FREE bonded specimen (no walls, no gravity, at rest): does the BrittleBeam
(RotBond) model keep its energy? The reference for Basalt's rot_bond on the same geometry
(docs/validation-rock.md, "Energy"; docs/reference-runs.md, "A free bonded specimen").

    /usr/bin/python3 tools/esys/free_specimen.py --geometry disc.h5 --output out/esys_free [--steps 3000]

The geometry is a Basalt geometry file (basalt-pack's HDF5: particles/id, position, radius; bonds/pairs),
read here with h5py (bonds/pairs hold particle ids) and handed to ESyS as it is: RotSphere(id, position, radius, mass 4/3 pi r^3), one
TaggedIdConnection per bond (lower id first, as Basalt stores it), tag 0. Physics as scenes/ucs.toml:
  * BrittleBeamPrms(youngsModulus=1e5, poissonsRatio=0.25, cohesion=--cohesion, tanAngle=1,
    meanR_scaling=True, truncated=1, beta1=1, beta2=1) on the bonds;
  * RotFrictionPrms(normalK=1e5, dynamicMu=0.4, staticMu=0.6, shearK=1e5, scaling=True) for the unbonded
    pairs, excluded for bonded ones;
  * LinDampingPrms and RotDampingPrms (viscosity --damping, maxIterations 50; --damping 0: none);
  * no walls, no gravity, dt --dt, --steps steps, 1 worker (--workers-dims to change).
Outputs in --output: energies.csv (step,kinetic_energy,linear_kinetic_energy,rotational_kinetic_energy,
bond_potential_energy,bonds every --every steps, row 0 the initial state; ESyS's SUM savers e_kin,
e_kin_linear, e_kin_rot and the bonds' potential_energy and count, printed by ESyS to 6 digits), and
ESyS's checkpoints cp_t=N_W.txt at the steps of --checkpoints. Exit 3 if ESyS is missing.
"""

import argparse
import math
import os
import subprocess
import sys

# tools/ (esysparticle's embedded interpreter does not add the script's folder either)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)
SAVERS = [("kinetic_energy", "particle", "e_kin"), ("linear_kinetic_energy", "particle", "e_kin_linear"),
          ("rotational_kinetic_energy", "particle", "e_kin_rot"),
          ("bond_potential_energy", "bonds", "potential_energy"), ("bonds", "bonds", "count")]


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--geometry", required=True, help="Basalt geometry (.h5) with bonds")
    p.add_argument("--output", required=True, help="output directory")
    p.add_argument("--steps", type=int, default=3000)
    p.add_argument("--dt", type=float, default=1e-4)
    p.add_argument("--every", type=int, default=10, help="energy rows every N steps")
    p.add_argument("--damping", type=float, default=0.002, help="LinDamping/RotDamping viscosity (0: none)")
    p.add_argument("--cohesion", type=float, default=100.0, help="BrittleBeam cohesion (strengths)")
    p.add_argument("--checkpoints", default="", help="comma-separated steps to checkpoint")
    p.add_argument("--workers-dims", default="1,1,1", help="ESyS worker grid 'nx,ny,nz'")
    p.add_argument("--particles", help=argparse.SUPPRESS)  # the child's copy of the geometry
    args = p.parse_args(argv)
    args.dims = [int(v) for v in args.workers_dims.split(",")]
    args.cps = [int(v) for v in args.checkpoints.split(",") if v]
    return args


def write_particles(geometry, path):
    """The geometry as plain text for the child (esysparticle's Python has no h5py): 'P id x y z r' lines,
    then 'B a b' lines with a < b."""
    import h5py
    with h5py.File(geometry, "r") as f:
        ids = f["particles/id"][:]
        pos = f["particles/position"][:]
        rad = f["particles/radius"][:]
        pairs = f["bonds/pairs"][:] if "bonds/pairs" in f else []
    with open(path, "w") as out:
        for i in range(len(ids)):
            out.write(f"P {int(ids[i])} {pos[i][0]!r} {pos[i][1]!r} {pos[i][2]!r} {rad[i]!r}\n")
        known = {int(i) for i in ids}
        for a, b in pairs:  # particle ids (basalt-geometry schema), lower first
            a, b = int(a), int(b)
            if a not in known or b not in known:
                raise KeyError(f"bonds/pairs: bond {a}-{b} names an unknown particle id")
            out.write(f"B {min(a, b)} {max(a, b)}\n")
    return len(ids), len(pairs)


def launch(argv):
    args = parse_args(argv)
    missing = bt.esys_missing()
    if missing:
        print(f"ESyS-Particle is not available: {', '.join(missing)} not on PATH "
              "(Debian package esys-particle). Nothing was run.", file=sys.stderr)
        return 3
    output = os.path.abspath(args.output)
    os.makedirs(output, exist_ok=True)
    try:
        n, nb = write_particles(args.geometry, os.path.join(output, "particles.txt"))
    except (OSError, KeyError) as e:
        print(f"error: {args.geometry}: cannot read a Basalt geometry: {e}", file=sys.stderr)
        return 2
    print(f"{args.geometry}: {n} particles, {nb} bonds", flush=True)
    workers = args.dims[0] * args.dims[1] * args.dims[2]
    cmd = bt.esys_command(__file__, workers + 1, list(argv) + [
        "--output", output, "--particles", os.path.join(output, "particles.txt")])
    rc = subprocess.call(cmd, env=bt.esys_env(), cwd=output)
    if rc != 0:
        print(f"esysparticle exited with {rc}", file=sys.stderr)
        return 1
    columns = []
    for name, _, field in SAVERS:
        with open(os.path.join(output, f"{field}.dat")) as f:
            columns.append([float(line) for line in f if line.strip()])
    rows = min(len(c) for c in columns)
    with open(os.path.join(output, "energies.csv"), "w") as f:
        f.write("step," + ",".join(s[0] for s in SAVERS) + "\n")
        for i in range(rows):
            f.write(f"{i * args.every}," + ",".join(f"{c[i]:.6g}" for c in columns) + "\n")
    last = [c[rows - 1] for c in columns]
    print(f"{rows} rows -> {os.path.join(output, 'energies.csv')}; last row: " +
          ", ".join(f"{s[0]} {v:.4g}" for s, v in zip(SAVERS, last)))
    return 0


def simulate(argv):
    """Runs inside esysparticle (MPI rank 0 = ESyS master)."""
    from esys.lsm import (RotSphere, BrittleBeamPrms, RotFrictionPrms, LinDampingPrms, RotDampingPrms,
                          ParticleScalarFieldSaverPrms, InteractionScalarFieldSaverPrms, CheckPointPrms)
    from esys.lsm.util import Vec3
    from esys.lsm.geometry import TaggedIdConnection

    args = parse_args(argv)
    os.chdir(args.output)
    particles, bonds = [], []
    with open(args.particles) as f:
        for line in f:
            w = line.split()
            if w[0] == "P":
                particles.append((int(w[1]), float(w[2]), float(w[3]), float(w[4]), float(w[5])))
            else:
                bonds.append((int(w[1]), int(w[2])))
    rmax = max(p[4] for p in particles)
    lo = [min(p[i + 1] for p in particles) - 4 * rmax for i in range(3)]
    hi = [max(p[i + 1] for p in particles) + 4 * rmax for i in range(3)]
    sim = bt.esys_simulation(args.dims, "RotSphere", 2.5 * rmax, 0.05, lo, hi, dt=args.dt, steps=args.steps)
    sim.createParticles([RotSphere(id=pid, posn=Vec3(x, y, z), radius=r, mass=4.0 / 3.0 * math.pi * r ** 3)
                         for (pid, x, y, z, r) in particles])
    sim.createConnections([TaggedIdConnection(a, b, 0) for (a, b) in bonds])
    sim.createInteractionGroup(BrittleBeamPrms(name="bonds", youngsModulus=1e5, poissonsRatio=0.25,
                                               cohesion=args.cohesion, tanAngle=1.0, tag=0, meanR_scaling=True,
                                               truncated=1.0, beta1=1.0, beta2=1.0))
    sim.createInteractionGroup(RotFrictionPrms(name="friction", normalK=1e5, dynamicMu=0.4, staticMu=0.6,
                                               shearK=1e5, scaling=True))
    sim.createExclusion("bonds", "friction")
    if args.damping > 0:
        sim.createInteractionGroup(LinDampingPrms(name="lin_damping", viscosity=args.damping, maxIterations=50))
        sim.createInteractionGroup(RotDampingPrms(name="rot_damping", viscosity=args.damping, maxIterations=50))
    for _, kind, field in SAVERS:
        common = dict(fieldName=field, fileName=f"{field}.dat", fileFormat="SUM", beginTimeStep=0,
                      endTimeStep=args.steps, timeStepIncr=args.every)
        if kind == "particle":
            sim.createFieldSaver(ParticleScalarFieldSaverPrms(**common))
        else:
            sim.createFieldSaver(InteractionScalarFieldSaverPrms(interactionName=kind, **common))
    for step in args.cps:
        sim.createCheckPointer(CheckPointPrms(fileNamePrefix="cp", beginTimeStep=step, endTimeStep=step,
                                              timeStepIncr=1))
    for _ in range(args.steps):
        sim.runTimeStep()
    sim.exit()


if __name__ == "__main__":
    if bt.esys_child():
        simulate(sys.argv[1:])  # inside esysparticle: sys.exit would skip MPI_Finalize
    else:
        sys.exit(launch(sys.argv[1:]))
