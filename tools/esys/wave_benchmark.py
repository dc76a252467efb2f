#!/usr/bin/python3
"""The seed paper's wave-propagation benchmark (BENCHMARK.md, Table 1) in ESyS-Particle 2.3.5.

Run it with the system Python; it checks that ESyS-Particle is installed and re-launches itself as
`mpirun -np W+1 esysparticle wave_benchmark.py ...` (one master + W workers):

    /usr/bin/python3 tools/esys/wave_benchmark.py --steps 2000 --fieldsaver --output out/esys1

Physics (ESyS conventions, verified in docs/reference-runs.md):
  * particles from a .geo file, mass = 4/3 pi r^3 (density 1), no rotation (NRotSphere);
  * NRotBond between the file's bonded pairs, K = 1000 N/mm, scaling=False, unbreakable
    (breakDistance is a strain, set huge); ESyS's rest length is r1 + r2, not the initial distance;
  * NRotElastic K = 1000, scaling=False, between touching pairs, excluded for bonded pairs;
  * a planar wall at z = 0 (normal +z), NRotElasticWall normalK = 1000 (ESyS applies pi r K overlap),
    prescribed position z_w(t) = A T/(2 pi) (1 - cos(2 pi t/T)) for t <= T/2 (A = 0.1 mm/ms, T = 1 ms),
    then at rest: the exact integral of the velocity pulse A sin(2 pi t/T). The wall is moved after
    step n to z_w(n dt), so that step n+1 computes forces with particles and wall both at time n dt;
  * dt = 1e-3 ms, no damping, no gravity; symplectic Euler (ESyS's own integrator).
Outputs in --output: ekin.csv (step,time,kinetic_energy; row k is the state after k steps, k = 0 the
initial state) with --fieldsaver, ESyS checkpoints with --checkpoint-every, timing.json always.
"""

import argparse
import json
import math
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
# tools/ (esysparticle's embedded interpreter does not add the script's folder either)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)
from basalt_tools import GeoError, read_geo  # noqa: E402

# The paper's reference cube: BASALT_REFERENCE_DIR (as for the tests), default tests/data of this checkout.
DEFAULT_GEOMETRY = bt.reference_cube()


def wall_position(t, amplitude, period):
    """Exact integral of the velocity pulse amplitude*sin(2 pi t/period), 0 <= t <= period/2."""
    t = min(max(t, 0.0), 0.5 * period)
    return amplitude * period / (2.0 * math.pi) * (1.0 - math.cos(2.0 * math.pi * t / period))


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--geometry", default=DEFAULT_GEOMETRY, help=".geo file (default %(default)s)")
    p.add_argument("--steps", type=int, default=10000)
    p.add_argument("--dt", type=float, default=1e-3, help="time step, ms")
    p.add_argument("--workers-dims", default="1,1,1", help="ESyS worker grid 'nx,ny,nz'")
    p.add_argument("--fieldsaver", action="store_true", help="save total kinetic energy every step")
    p.add_argument("--checkpoint-every", type=int, default=0, help="ESyS checkpoint every N steps (0: none)")
    p.add_argument("--output", default="esys_wave_out", help="output directory")
    p.add_argument("--stiffness", type=float, default=1000.0, help="K of bonds, contacts, wall, N/mm")
    p.add_argument("--amplitude", type=float, default=0.1, help="wall velocity amplitude, mm/ms (0: static)")
    p.add_argument("--period", type=float, default=1.0, help="wall pulse period, ms")
    p.add_argument("--grid-spacing", type=float, default=0.0, help="ESyS gridSpacing (default 2.5 r_max)")
    p.add_argument("--verlet-dist", type=float, default=0.2, help="ESyS verletDist, mm")
    p.add_argument("--pad-top", type=float, default=0.5, help="domain padding above, fraction of height")
    p.add_argument("--generate-side", type=float, default=0.0,
                   help="if --geometry is missing, generate a GenGeo cube of this side there first")
    args = p.parse_args(argv)
    try:
        dims = bt.parse_dims(args.workers_dims)
    except ValueError:
        p.error(f"--workers-dims: expected three positive integers 'nx,ny,nz', got '{args.workers_dims}'")
    args.dims = dims
    if args.steps < 1:
        p.error(f"--steps must be positive, got {args.steps}")
    if args.dt <= 0:
        p.error(f"--dt must be positive, got {args.dt}")
    if args.checkpoint_every < 0:
        p.error(f"--checkpoint-every must be >= 0, got {args.checkpoint_every}")
    return args


def launch(argv):
    """Checks the installation and the input, then re-runs this script under mpirun + esysparticle."""
    args = parse_args(argv)
    missing = bt.esys_missing()
    if missing:
        print(f"ESyS-Particle is not available: {', '.join(missing)} not on PATH "
              "(Debian package esys-particle). Nothing was run.", file=sys.stderr)
        return 3
    if not os.path.exists(args.geometry) and args.generate_side > 0:
        gen = os.path.join(HERE, "..", "bench", "gengeo_cube.py")
        print(f"{args.geometry} missing: generating a {args.generate_side} mm GenGeo cube (slow)", flush=True)
        rc = subprocess.call(["/usr/bin/python3", gen, "--side", str(args.generate_side), "--output", args.geometry])
        if rc != 0:
            return rc
    try:
        read_geo(args.geometry)  # validate before starting MPI: errors name the file and line
    except GeoError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    try:
        os.makedirs(args.output, exist_ok=True)
        probe = os.path.join(args.output, ".writable")
        open(probe, "w").close()
        os.remove(probe)
    except OSError as e:
        print(f"error: output directory {args.output}: {e.strerror}", file=sys.stderr)
        return 2
    workers = args.dims[0] * args.dims[1] * args.dims[2]
    # Workers write checkpoints relative to their own working directory: start every rank in --output.
    output = os.path.abspath(args.output)
    child_args = list(argv) + ["--geometry", os.path.abspath(args.geometry), "--output", output]
    return bt.esys_relaunch(__file__, workers + 1, child_args, cwd=output)


def simulate(argv):
    """Runs inside esysparticle (MPI rank 0 = ESyS master)."""
    from esys.lsm import (NRotSphere, NRotBondPrms, NRotElasticPrms, NRotElasticWallPrms,
                          ParticleScalarFieldSaverPrms, CheckPointPrms, Runnable)
    from esys.lsm.util import Vec3
    from esys.lsm.geometry import TaggedIdConnection

    args = parse_args(argv)
    geometry = os.path.abspath(args.geometry)
    os.makedirs(args.output, exist_ok=True)
    os.chdir(args.output)  # ESyS writes savers and checkpoints relative to the working directory

    t_setup = time.perf_counter()
    box_lo, box_hi, particles, bonds = read_geo(geometry)
    rmax = max(p[4] for p in particles)
    lo = [min(box_lo[i], min(p[i + 1] - p[4] for p in particles)) for i in range(3)]
    hi = [max(box_hi[i], max(p[i + 1] + p[4] for p in particles)) for i in range(3)]
    pad = 2.0 * rmax
    dom_lo = [lo[0] - pad, lo[1] - pad, lo[2] - pad]
    dom_hi = [hi[0] + pad, hi[1] + pad, hi[2] + args.pad_top * (hi[2] - lo[2])]
    grid = args.grid_spacing if args.grid_spacing > 0 else 2.5 * rmax
    workers = args.dims[0] * args.dims[1] * args.dims[2]

    sim = bt.esys_simulation(args.dims, "NRotSphere", grid, args.verlet_dist, dom_lo, dom_hi, dt=args.dt,
                             steps=args.steps)
    sim.createParticles([NRotSphere(id=pid, posn=Vec3(x, y, z), radius=r, mass=4.0 / 3.0 * math.pi * r ** 3)
                         for (pid, x, y, z, r, tag) in particles])
    sim.createConnections([TaggedIdConnection(a, b, 0) for (a, b, t) in bonds])
    K = args.stiffness
    sim.createInteractionGroup(NRotBondPrms(name="bonds", normalK=K, breakDistance=1.0e9, tag=0, scaling=False))
    sim.createInteractionGroup(NRotElasticPrms(name="contacts", normalK=K, scaling=False))
    sim.createExclusion("bonds", "contacts")
    wall_z0 = 0.0
    sim.createWall(name="base", posn=Vec3(0.0, 0.0, wall_z0), normal=Vec3(0.0, 0.0, 1.0))
    sim.createInteractionGroup(NRotElasticWallPrms(name="base_wall", wallName="base", normalK=K))

    class WallPulse(Runnable):
        """After step n, places the wall at z_w(n dt): ESyS runs post-step runnables after the savers."""

        def __init__(self):
            Runnable.__init__(self)
            self.step = 0
            self.z = 0.0

        def run(self):
            self.step += 1
            z = wall_position(self.step * args.dt, args.amplitude, args.period)
            if z != self.z:
                sim.moveWallBy("base", Vec3(0.0, 0.0, z - self.z))
                self.z = z

    pulse = WallPulse()
    if args.amplitude != 0.0:
        sim.addPostTimeStepRunnable(pulse)
    if args.fieldsaver:
        sim.createFieldSaver(ParticleScalarFieldSaverPrms(fieldName="e_kin", fileName="ekin_raw.dat", fileFormat="SUM",
                                                          beginTimeStep=0, endTimeStep=args.steps, timeStepIncr=1))
    if args.checkpoint_every > 0:
        sim.createCheckPointer(CheckPointPrms(fileNamePrefix="checkpoint", beginTimeStep=0, endTimeStep=args.steps,
                                              timeStepIncr=args.checkpoint_every))
    setup_s = time.perf_counter() - t_setup
    n = len(particles)
    print(f"setup: {n} particles, {len(bonds)} bonds, domain {dom_lo} .. {dom_hi}, gridSpacing {grid}, "
          f"verletDist {args.verlet_dist}, {workers} worker(s) {args.dims}: {setup_s:.2f} s", flush=True)

    t0 = time.perf_counter()
    sim.runTimeStep()  # first step builds the neighbour lists: timed separately
    t1 = time.perf_counter()
    for _ in range(args.steps - 1):
        sim.runTimeStep()
    t2 = time.perf_counter()
    sim.exit()
    loop_s = t2 - t0
    result = {
        "geometry": geometry, "particles": n, "bonds": len(bonds), "steps": args.steps, "dt": args.dt,
        "workers": workers, "workers_dims": args.dims, "fieldsaver": args.fieldsaver,
        "checkpoint_every": args.checkpoint_every, "setup_s": setup_s, "first_step_s": t1 - t0,
        "loop_s": loop_s, "particle_steps_per_s": n * args.steps / loop_s,
        "particle_steps_per_s_after_first": n * (args.steps - 1) / (t2 - t1) if args.steps > 1 else None,
        "grid_spacing": grid, "verlet_dist": args.verlet_dist, "wall_final_z": pulse.z,
    }
    if args.fieldsaver:
        with open("ekin_raw.dat") as f:
            values = [float(line) for line in f if line.strip()]
        with open("ekin.csv.tmp", "w") as f:
            f.write("step,time,kinetic_energy\n")
            for step, e in enumerate(values):
                f.write(f"{step},{step * args.dt:.6g},{e:.10g}\n")
        os.replace("ekin.csv.tmp", "ekin.csv")
        result["ekin_rows"] = len(values)
    with open("timing.json", "w") as f:
        json.dump(result, f, indent=1)
    print(f"time-stepping loop: {loop_s:.3f} s for {args.steps} steps "
          f"(first step {t1 - t0:.3f} s): {result['particle_steps_per_s'] / 1e6:.3f} M particle-steps/s", flush=True)


if __name__ == "__main__":
    if bt.esys_child():
        simulate(sys.argv[1:])
    else:
        sys.exit(launch(sys.argv[1:]))
