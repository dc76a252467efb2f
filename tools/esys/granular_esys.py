#!/usr/bin/python3
"""ESyS-Particle 2.3.5 reference run for Basalt's scenes/granular-esys.toml: a granular column collapse.

Run it with the system Python; it checks for the packages and re-launches itself as
`mpirun -np W+1 esysparticle granular_esys.py ...` (one master + W workers):

    /usr/bin/python3 tools/esys/granular_esys.py --geometry-out out/gran/column.geo --output out/gran
    /usr/bin/python3 tools/esys/granular_esys.py --geometry out/gran/column.geo --perturb 0,1e-9 --output out/gran_p

Geometry: GenGeo InsertGenerator3D, unbonded spheres, radii 0.5-1.0, in the box [0,16]x[0,16]x[0,24]
(planes on all six faces; insertFails 1000, maxIterations 1000, tolerance 1e-6, tag 1, GenGeo's seeding
off: deterministic). Written as an LSMGeometry .geo to --geometry-out (generated only when --geometry is
not given). Physics (conventions in docs/reference-runs.md, "Granular conventions"):
  * RotSphere particles, mass = 4/3 pi r^3 (density 1), moment of inertia 0.4 m r^2 (ESyS's own);
  * RotFrictionPrms(normalK=1000, dynamicMu=0.6, staticMu=0.6, shearK=1000, scaling=False, rigid=False)
    between all pairs;
  * NRotElasticWallPrms(normalK=1000) walls (ESyS applies 3.141592654 r K overlap): z=0 (+z), x=0 (+x),
    y=0 (+y), y=16 (-y); none at x=16, so the column collapses towards +x;
  * GravityPrms(acceleration=(0,0,-1)); LinDampingPrms and RotDampingPrms, viscosity 0.01,
    maxIterations 100;
  * dt = 1e-3, 20,000 steps, verletDist 0.1, gridSpacing 2.5 r_max.
Outputs in --output: ekin.csv (step,kinetic_energy every --ekin-every steps, row 0 the initial state;
ESyS's e_kin = translational + rotational, printed to 6 digits), positions.csv (id,x,y,z,r after the last
step, read from ESyS's checkpoint, 9 digits), timing.json.
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

BOX = (16.0, 16.0, 24.0)


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--geometry", help="existing .geo column (default: generate one with GenGeo)")
    p.add_argument("--geometry-out", help="where to write the generated .geo (default OUTPUT/column.geo)")
    p.add_argument("--steps", type=int, default=20000)
    p.add_argument("--dt", type=float, default=1e-3)
    p.add_argument("--ekin-every", type=int, default=10)
    p.add_argument("--workers-dims", default="1,1,1", help="ESyS worker grid 'nx,ny,nz'")
    p.add_argument("--output", default="esys_granular_out", help="output directory")
    p.add_argument("--perturb", default="", help="ID,DZ: move particle ID by DZ along z before the run")
    p.add_argument("--verlet-dist", type=float, default=0.1)
    p.add_argument("--domain-x", type=float, default=256.0, help="upper x of ESyS's domain (runout room)")
    p.add_argument("--rmin", type=float, default=0.5)
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
    if args.steps < 1 or args.ekin_every < 1:
        p.error("--steps and --ekin-every must be positive")
    return args


def generate_column(path, rmin, rmax):
    """GenGeo column in BOX, written to path (.geo); deterministic (seeding off)."""
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
        tmp = path + ".tmp"
        table.write(tmp, 1)
        os.replace(tmp, path)
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def launch(argv):
    args = parse_args(argv)
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
        geometry = args.geometry_out or os.path.join(output, "column.geo")
        t0 = time.perf_counter()
        generate_column(geometry, args.rmin, args.rmax)
        print(f"generated {geometry} in {time.perf_counter() - t0:.1f} s", flush=True)
    try:
        _, _, particles, bonds = read_geo(geometry)
    except GeoError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if bonds:
        print(f"note: {geometry} has {len(bonds)} bonds; they are ignored (granular run)", file=sys.stderr)
    if args.perturb_id is not None and args.perturb_id not in {p[0] for p in particles}:
        print(f"error: --perturb: no particle with id {args.perturb_id} in {geometry}", file=sys.stderr)
        return 2
    workers = args.dims[0] * args.dims[1] * args.dims[2]
    child_args = list(argv) + ["--geometry", os.path.abspath(geometry), "--output", output]
    return bt.esys_relaunch(__file__, workers + 1, child_args, cwd=output)


def read_checkpoint_positions(prefix, step, workers):
    """id -> (x, y, z, r) from ESyS's checkpoint files PREFIX_t=STEP_W.txt (one per worker W >= 1)."""
    rows, _ = bt.read_esys_checkpoint(prefix, step, workers)
    return {pid: (v[0], v[1], v[2], v[3]) for pid, v in rows.items()}


def simulate(argv):
    """Runs inside esysparticle (MPI rank 0 = ESyS master)."""
    from esys.lsm import (RotSphere, RotFrictionPrms, NRotElasticWallPrms, GravityPrms,
                          LinDampingPrms, RotDampingPrms, ParticleScalarFieldSaverPrms, CheckPointPrms)
    from esys.lsm.util import Vec3

    args = parse_args(argv)
    os.chdir(args.output)
    t_setup = time.perf_counter()
    _, _, particles, _ = read_geo(args.geometry)
    rmax = max(p[4] for p in particles)
    grid = 2.5 * rmax
    workers = args.dims[0] * args.dims[1] * args.dims[2]
    # Room for the runout towards +x (no wall at x = 16; the walls are frictionless, so the bottom layer
    # slides far): ESyS drops particles that leave its domain. With x <= 96, 47 particles were lost by
    # step 20,000; with x <= 256 none are (checked at the end).
    dom_lo = (-2.0 * rmax, -2.0 * rmax, -2.0 * rmax)
    dom_hi = (args.domain_x, BOX[1] + 2.0 * rmax, BOX[2] + 4.0 * rmax)

    sim = bt.esys_simulation(args.dims, "RotSphere", grid, args.verlet_dist, dom_lo, dom_hi, dt=args.dt,
                             steps=args.steps)
    spheres = []
    for (pid, x, y, z, r, tag) in particles:
        if pid == args.perturb_id:
            z += args.perturb_dz
        spheres.append(RotSphere(id=pid, posn=Vec3(x, y, z), radius=r, mass=4.0 / 3.0 * math.pi * r ** 3))
    sim.createParticles(spheres)
    sim.createInteractionGroup(RotFrictionPrms(name="friction", normalK=1000.0, dynamicMu=0.6, staticMu=0.6,
                                               shearK=1000.0, scaling=False, rigid=False))
    for name, posn, normal in (("floor", (0, 0, 0), (0, 0, 1)), ("back", (0, 0, 0), (1, 0, 0)),
                               ("side0", (0, 0, 0), (0, 1, 0)), ("side1", (0, BOX[1], 0), (0, -1, 0))):
        sim.createWall(name=name, posn=Vec3(*posn), normal=Vec3(*normal))
        sim.createInteractionGroup(NRotElasticWallPrms(name=name + "_wall", wallName=name, normalK=1000.0))
    sim.createInteractionGroup(GravityPrms(name="gravity", acceleration=Vec3(0.0, 0.0, -1.0)))
    sim.createInteractionGroup(LinDampingPrms(name="lin_damping", viscosity=0.01, maxIterations=100))
    sim.createInteractionGroup(RotDampingPrms(name="rot_damping", viscosity=0.01, maxIterations=100))
    sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="ekin_raw.dat", fileFormat="SUM",
                                                      beginTimeStep=0, endTimeStep=args.steps,
                                                      timeStepIncr=args.ekin_every))
    sim.createCheckPointer(CheckPointPrms(fileNamePrefix="final", beginTimeStep=args.steps,
                                          endTimeStep=args.steps, timeStepIncr=1))
    setup_s = time.perf_counter() - t_setup
    print(f"setup: {len(particles)} particles, {workers} worker(s), gridSpacing {grid}, "
          f"verletDist {args.verlet_dist}: {setup_s:.2f} s", flush=True)
    t0 = time.perf_counter()
    for _ in range(args.steps):
        sim.runTimeStep()
    loop_s = time.perf_counter() - t0
    sim.exit()

    with open("ekin_raw.dat") as f:
        values = [float(line) for line in f if line.strip()]
    with open("ekin.csv", "w") as f:
        f.write("step,kinetic_energy\n")
        for i, e in enumerate(values):
            f.write(f"{i * args.ekin_every},{e:.6g}\n")
    parts = read_checkpoint_positions("final", args.steps, workers)
    with open("positions.csv", "w") as f:
        f.write("id,x,y,z,r\n")
        for pid in sorted(parts):
            x, y, z, r = parts[pid]
            f.write(f"{pid},{x:.9g},{y:.9g},{z:.9g},{r:.9g}\n")
    result = {"geometry": args.geometry, "particles": len(particles), "particles_at_end": len(parts),
              "steps": args.steps, "dt": args.dt, "workers_dims": args.dims, "perturb": args.perturb,
              "setup_s": setup_s, "loop_s": loop_s, "ekin_rows": len(values)}
    with open("timing.json", "w") as f:
        json.dump(result, f, indent=1)
    print(f"time-stepping loop: {loop_s:.1f} s for {args.steps} steps; {len(parts)} particles at the end",
          flush=True)
    if len(parts) != len(particles):
        print(f"WARNING: {len(particles) - len(parts)} particles left ESyS's domain (raise --domain-x)", flush=True)


if __name__ == "__main__":
    if bt.esys_child():
        simulate(sys.argv[1:])
    else:
        sys.exit(launch(sys.argv[1:]))
