#!/usr/bin/python3
"""ESyS-Particle 2.3.5 reference run for Basalt's scenes/ucs-esys.toml: the uniaxial compression test of
ESyS's rot_compress example on a GenGeo box.

Run it with the system Python; it checks for the packages and re-launches itself as
`mpirun -np W+1 esysparticle ucs_esys.py ...` (one master + W workers):

    /usr/bin/python3 tools/esys/ucs_esys.py --geometry-out out/ucs-esys/box.geo --output out/ucs-esys/base
    /usr/bin/python3 tools/esys/ucs_esys.py --geometry docs/data/esys-ucs/box.geo --output out/ucs-esys/base
    /usr/bin/python3 tools/esys/ucs_esys.py --geometry docs/data/esys-ucs/box.geo --perturb 0,1e-12 --output out/ucs-esys/pert

Geometry: GenGeo InsertGenerator3D, radii 0.25-1.0, in the box [0,10]x[0,10]x[0,20] (planes on all six
faces; insertFails 1000, maxIterations 1000, tolerance 1e-6, particle tag 1, GenGeo's seeding off:
deterministic), bonds between pairs closer than 1e-5 (bond tag 0): generateBonds(0, 1e-5, 0). Written as
a .geo to --geometry-out (generated only when --geometry is not given). Physics (rot_compress's, the
conventions measured in docs/reference-runs.md):
  * RotSphere particles, mass 4/3 pi r^3 (density 1);
  * BrittleBeamPrms(youngsModulus=1e5, poissonsRatio=0.25, cohesion=100, tanAngle=1, tag=0,
    meanR_scaling=True, truncated=1, beta1=1, beta2=1) on the .geo's bonds;
  * FrictionPrms(youngsModulus=1e5, poissonsRatio=0.25, dynamicMu=0.4, staticMu=0.6) for the other pairs,
    createExclusion(bonds, friction);
  * walls bottom_wall z=0 (+z) and top_wall z=20 (-z), NRotElasticWallPrms(normalK=1e5), each moved
    towards the other by the tutorial's WallLoaderRunnable (pre-time-step) at 0.03 mm/ms, rampTime 2000;
  * LinDampingPrms and RotDampingPrms, viscosity 0.002, maxIterations 50; no gravity;
  * dt = 5e-5, 22,000 steps; gridSpacing 2.5 r_max, verletDist 0.1 (--verlet-dist).
`--collect-only --output DIR` writes DIR/ucs.csv from the savers' files of a run stopped early.
Outputs in --output: ucs.csv (step, the wall forces and positions (z), the bond count and e_kin every
--every steps, row 0 the initial state; wall vectors from RAW_SERIES savers, scalars from SUM savers,
6 significant digits), timing.json (setup and stepping-loop wall times).
"""

import argparse
import json
import math
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
# tools/ (esysparticle's embedded interpreter does not add the script's folder either)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)
from basalt_tools import GeoError, read_geo  # noqa: E402

BOX = (10.0, 10.0, 20.0)


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--geometry", help="existing .geo specimen (default: generate one with GenGeo)")
    p.add_argument("--geometry-out", help="where to write the generated .geo (default OUTPUT/box.geo)")
    p.add_argument("--steps", type=int, default=22000)
    p.add_argument("--dt", type=float, default=5e-5)
    p.add_argument("--speed", type=float, default=0.03, help="each wall's final speed, mm/ms")
    p.add_argument("--ramp-steps", type=int, default=2000, help="WallLoaderRunnable rampTime")
    p.add_argument("--every", type=int, default=10, help="saver interval, steps")
    p.add_argument("--workers-dims", default="1,1,1", help="ESyS worker grid 'nx,ny,nz'")
    p.add_argument("--output", default="esys_ucs_out", help="output directory")
    p.add_argument("--perturb", default="", help="ID,DZ: move particle ID by DZ along z before the run")
    p.add_argument("--verlet-dist", type=float, default=0.1)
    p.add_argument("--collect-only", action="store_true",
                   help="only write OUTPUT/ucs.csv from the savers' files (a run stopped early)")
    p.add_argument("--rmin", type=float, default=0.25)
    p.add_argument("--rmax", type=float, default=1.0)
    args = p.parse_args(argv)
    try:
        dims = bt.parse_dims(args.workers_dims)
    except ValueError:
        p.error(f"--workers-dims: expected three positive integers 'nx,ny,nz', got '{args.workers_dims}'")
    args.dims = dims
    args.perturb_id, args.perturb_dz = None, 0.0
    if args.perturb:
        try:
            pid, dz = args.perturb.split(",")
            args.perturb_id, args.perturb_dz = int(pid), float(dz)
        except ValueError:
            p.error(f"--perturb: expected 'ID,DZ', got '{args.perturb}'")
    if args.steps < 1 or args.every < 1 or args.ramp_steps < 1:
        p.error("--steps, --every and --ramp-steps must be positive")
    return args


def generate_box(path, rmin, rmax):
    """GenGeo bonded box in BOX, written to path (.geo); deterministic (seeding off)."""
    from gengeo import Vector3, BoxWithPlanes3D, Plane, MNTable3D, InsertGenerator3D
    sys.stdout.flush()
    saved = os.dup(1)  # GenGeo prints progress from C++ to fd 1
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.close(devnull)
    try:
        lo, hi = Vector3(0.0, 0.0, 0.0), Vector3(*BOX)
        box = BoxWithPlanes3D(lo, hi)
        for origin, normal in ((lo, (1, 0, 0)), (lo, (0, 1, 0)), (lo, (0, 0, 1)),
                               (hi, (-1, 0, 0)), (hi, (0, -1, 0)), (hi, (0, 0, -1))):
            box.addPlane(Plane(origin, Vector3(*normal)))
        table = MNTable3D(lo, hi, 2.5 * rmax, 1)
        InsertGenerator3D(rmin, rmax, 1000, 1000, 1e-6, False).generatePacking(box, table, 0, 1)
        table.generateBonds(0, 1e-5, 0)
        tmp = path + ".tmp"
        table.write(tmp, 1)
        os.replace(tmp, path)
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def launch(argv):
    args = parse_args(argv)
    if args.collect_only:
        rows = collect(args.output, args.every)
        print(f"{os.path.join(args.output, 'ucs.csv')}: {rows} rows (steps 0..{(rows - 1) * args.every})")
        return 0
    missing = bt.esys_missing()
    if missing:
        print(f"ESyS-Particle is not available: {', '.join(missing)} not on PATH "
              "(Debian package esys-particle). Nothing was run.", file=sys.stderr)
        return 3
    os.makedirs(args.output, exist_ok=True)
    output = os.path.abspath(args.output)
    geometry = args.geometry
    if not geometry:
        try:
            import gengeo  # noqa: F401
        except ImportError:
            print("GenGeo is not available (Debian package python3-gengeo); pass --geometry. Nothing was run.",
                  file=sys.stderr)
            return 3
        geometry = args.geometry_out or os.path.join(output, "box.geo")
        t0 = time.perf_counter()
        generate_box(geometry, args.rmin, args.rmax)
        print(f"generated {geometry} in {time.perf_counter() - t0:.1f} s", flush=True)
    try:
        _, _, particles, bonds = read_geo(geometry)
    except GeoError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(f"{geometry}: {len(particles)} particles, {len(bonds)} bonds", flush=True)
    if args.perturb_id is not None and args.perturb_id not in {p[0] for p in particles}:
        print(f"error: --perturb: no particle with id {args.perturb_id} in {geometry}", file=sys.stderr)
        return 2
    workers = args.dims[0] * args.dims[1] * args.dims[2]
    child_args = list(argv) + ["--geometry", os.path.abspath(geometry), "--output", output]
    return bt.esys_relaunch(__file__, workers + 1, child_args, cwd=output)


def read_sum(path):
    with open(path) as f:
        return [float(line) for line in f if line.strip()]


def read_raw_series(path):
    """RAW_SERIES wall saver: one line per saved step, 3 numbers per wall in the order given."""
    with open(path) as f:
        return [[float(w) for w in line.split()] for line in f if line.strip()]


def collect(output, every):
    """ucs.csv from the savers' files in OUTPUT (also for a run stopped early: the rows all savers hold)."""
    nb, ek = read_sum(os.path.join(output, "nbonds.dat")), read_sum(os.path.join(output, "ekin.dat"))
    force = read_raw_series(os.path.join(output, "out_Force.dat"))
    posn = read_raw_series(os.path.join(output, "out_Position.dat"))
    rows = min(len(nb), len(ek), len(force), len(posn))
    with open(os.path.join(output, "ucs.csv"), "w") as f:
        f.write("step,bottom_fz,top_fz,bottom_z,top_z,bond_count,kinetic_energy\n")
        for i in range(rows):
            if len(force[i]) < 6 or len(posn[i]) < 6:  # a line being written when the run stopped
                break
            f.write(f"{i * every},{force[i][2]:.6g},{force[i][5]:.6g},{posn[i][2]:.9g},{posn[i][5]:.9g},"
                    f"{nb[i]:.0f},{ek[i]:.6g}\n")
    return rows


def simulate(argv):
    """Runs inside esysparticle (MPI rank 0 = ESyS master)."""
    from esys.lsm import (RotSphere, BrittleBeamPrms, FrictionPrms, NRotElasticWallPrms,
                          LinDampingPrms, RotDampingPrms, ParticleScalarFieldSaverPrms,
                          InteractionScalarFieldSaverPrms, WallVectorFieldSaverPrms, Runnable)
    from esys.lsm.util import Vec3
    from esys.lsm.geometry import TaggedIdConnection

    args = parse_args(argv)
    os.chdir(args.output)
    t_setup = time.perf_counter()
    _, _, particles, bonds = read_geo(args.geometry)
    rmax = max(p[4] for p in particles)
    workers = args.dims[0] * args.dims[1] * args.dims[2]
    sim = bt.esys_simulation(args.dims, "RotSphere", 2.5 * rmax, args.verlet_dist, (-2.0 * rmax, -2.0 * rmax, -2.0 * rmax),
                             (BOX[0] + 2.0 * rmax, BOX[1] + 2.0 * rmax, BOX[2] + 2.0 * rmax), dt=args.dt, steps=args.steps)
    spheres = []
    for (pid, x, y, z, r, tag) in particles:
        if pid == args.perturb_id:
            z += args.perturb_dz
        s = RotSphere(id=pid, posn=Vec3(x, y, z), radius=r, mass=4.0 / 3.0 * math.pi * r ** 3)
        s.setTag(tag)
        spheres.append(s)
    sim.createParticles(spheres)
    sim.createConnections([TaggedIdConnection(a, b, t) for (a, b, t) in bonds])
    sim.createWall(name="bottom_wall", posn=Vec3(0.0, 0.0, 0.0), normal=Vec3(0.0, 0.0, 1.0))
    sim.createWall(name="top_wall", posn=Vec3(0.0, 0.0, BOX[2]), normal=Vec3(0.0, 0.0, -1.0))
    sim.createInteractionGroup(BrittleBeamPrms(name="pp_bonds", youngsModulus=1.0e5, poissonsRatio=0.25,
                                               cohesion=100.0, tanAngle=1.0, tag=0, meanR_scaling=True,
                                               truncated=1.0, beta1=1.0, beta2=1.0))
    sim.createInteractionGroup(FrictionPrms(name="friction", youngsModulus=1.0e5, poissonsRatio=0.25,
                                            dynamicMu=0.4, staticMu=0.6))
    sim.createExclusion(interactionName1="pp_bonds", interactionName2="friction")
    for w in ("bottom_wall", "top_wall"):
        sim.createInteractionGroup(NRotElasticWallPrms(name=w + "_repel", wallName=w, normalK=1.0e5))
    sim.createInteractionGroup(LinDampingPrms(name="damping1", viscosity=0.002, maxIterations=50))
    sim.createInteractionGroup(RotDampingPrms(name="damping2", viscosity=0.002, maxIterations=50))

    class WallLoaderRunnable(Runnable):
        """The tutorial's WallLoader.py (Doc/Tutorial/examples), startTime 0."""

        def __init__(self, name, v, ramp):
            Runnable.__init__(self)
            self.name, self.v, self.ramp, self.dt, self.nt = name, v, ramp, sim.getTimeStepSize(), 0

        def run(self):
            f = float(self.nt) / float(self.ramp) if self.nt < self.ramp else 1.0
            sim.moveWallBy(self.name, Vec3(0.0, 0.0, f * self.v * self.dt))
            self.nt += 1

    loaders = [WallLoaderRunnable("top_wall", -args.speed, args.ramp_steps),
               WallLoaderRunnable("bottom_wall", args.speed, args.ramp_steps)]
    for wl in loaders:
        sim.addPreTimeStepRunnable(wl)
    end, every = args.steps, args.every
    sim.createFieldSaver(InteractionScalarFieldSaverPrms(interactionName="pp_bonds", fieldName="count",
                                                         fileName="nbonds.dat", fileFormat="SUM", beginTimeStep=0,
                                                         endTimeStep=end, timeStepIncr=every))
    sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="ekin.dat", fileFormat="SUM",
                                                      beginTimeStep=0, endTimeStep=end, timeStepIncr=every))
    for field in ("Force", "Position"):
        sim.createFieldSaver(WallVectorFieldSaverPrms(wallName=["bottom_wall", "top_wall"], fieldName=field,
                                                      fileName=f"out_{field}.dat", fileFormat="RAW_SERIES",
                                                      beginTimeStep=0, endTimeStep=end, timeStepIncr=every))
    setup_s = time.perf_counter() - t_setup
    print(f"setup: {len(particles)} particles, {len(bonds)} bonds, {workers} worker(s), gridSpacing "
          f"{2.5 * rmax}, verletDist {args.verlet_dist}: {setup_s:.2f} s", flush=True)
    t0 = time.perf_counter()
    for _ in range(args.steps):
        sim.runTimeStep()
    loop_s = time.perf_counter() - t0
    sim.exit()

    rows = collect(".", every)
    result = {"geometry": args.geometry, "particles": len(particles), "bonds": len(bonds), "steps": args.steps,
              "dt": args.dt, "verlet_dist": args.verlet_dist, "workers_dims": args.dims, "perturb": args.perturb,
              "setup_s": setup_s, "loop_s": loop_s, "rows": rows}
    with open("timing.json", "w") as f:
        json.dump(result, f, indent=1)
    print(f"time-stepping loop: {loop_s:.1f} s for {args.steps} steps; {rows} rows in ucs.csv", flush=True)


if __name__ == "__main__":
    if bt.esys_child():
        simulate(sys.argv[1:])
    else:
        sys.exit(launch(sys.argv[1:]))
