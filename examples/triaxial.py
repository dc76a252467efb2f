"""Triaxial tests of a bonded rock specimen, from Python: pack a box of rotating spheres joined by brittle beam
bonds (scenes/ucs.toml's rock), close six servo walls on it until it holds a confining pressure on every face
(stage 1), then load it axially at a constant strain rate with the platens while the four lateral walls keep
the pressure (stage 2), until the deviatoric stress has fallen below 80 % of its peak. The same specimen at
several confining pressures. Units: mm, ms, N (N/mm^2 = MPa). One rank.

    python3 examples/triaxial.py            # a 10 x 10 x 20 mm box of ~5,000 spheres at 5, 10, 20 N/mm^2 (1-2 min)
    python3 examples/triaxial.py --quick    # the test: a 5 x 5 x 10 mm box of ~400 spheres at 5, 20 N/mm^2 (~5 s)

Writes out/examples/triaxial/stress_strain.png and stress_strain.csv (per pressure and every 50 steps: step,
time, axial and volumetric strain, axial, lateral and deviatoric stress, intact and broken bonds), and prints
each test's peak. Axial stress: the mean of the two platens' forces over the cross-section between the lateral
walls; lateral stress: the mean of the four lateral walls' forces over their faces; axial strain: the platens'
closure over the height at the start of stage 2; volumetric strain: the box's volume change over its volume then
(all from the walls' positions and forces, sim.walls). Intact and broken bonds: sim.bond_count() and
sim.broken_bonds() in the same callback.
"""

import argparse
import csv
from pathlib import Path

import numpy as np

import basalt

ROOT = Path(__file__).resolve().parents[1]

# The six walls: name -> (axis, side). side -1: the wall at the low end of the axis (its normal points +axis).
WALLS = {"x_low": (0, -1), "x_high": (0, 1), "y_low": (1, -1), "y_high": (1, 1),
         "bottom": (2, -1), "top": (2, 1)}
LATERAL = ("x_low", "x_high", "y_low", "y_high")


def scene(geometry, out, size, pressure, gain, max_speed):
    """scenes/ucs.toml's rock (BrittleBeam rot_bond bonds, rot_friction contacts, light damping) in a box of six
    walls, each a servo holding `pressure` on its face of the specimen as packed (target_stress x area: a fixed
    force; the faces change by the strains, ~0.2 %). Fields: the bonds still intact and broken every 50 steps
    (the Python API has no bond count of its own: they are read from fields.csv after the run)."""
    walls = []
    for name, (axis, side) in WALLS.items():
        point, normal = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        point[axis] = float(size[axis]) if side > 0 else 0.0
        normal[axis] = -float(side)
        a, b = [size[k] for k in range(3) if k != axis]
        walls.append({"name": name, "point": point, "normal": normal, "K": 1.0e5, "stiffness": "esys_pi_r",
                      "motion": {"type": "servo", "target_stress": pressure, "area": float(a * b),
                                 "gain": gain, "max_speed": max_speed}})
    return {
        "units": {"length": "mm", "time": "ms", "force": "N"},
        "geometry": {"file": str(geometry)},
        "material": {"density": 1.0},
        "particles": {"rotation": True},
        "run": {"dt": 1.0e-4, "skin": 0.05},
        "interactions": [
            {"name": "bonds", "type": "rot_bond", "youngs_modulus": 1.0e5, "poissons_ratio": 0.25,
             "radius_scaling": "mean", "cohesion": 100.0, "tan_friction_angle": 1.0, "criterion": "esys",
             "rest_length": "sum_of_radii"},
            {"name": "contacts", "type": "rot_friction", "K": 1.0e5, "Ks": 1.0e5, "mu": 0.6, "mu_dynamic": 0.4,
             "scaling": True},
        ],
        "walls": walls,
        "body_forces": [{"type": "linear_damping", "viscosity": 0.002, "iterations": 50},
                        {"type": "rotational_damping", "viscosity": 0.002, "iterations": 50}],
        "output": {"directory": str(out),
                   "fields": [{"type": "bond_count", "every": 50}, {"type": "broken_bonds", "every": 50}]},
    }


def stresses(sim):
    """Collective: the specimen's state from the six walls (their positions bound it): axial stress, lateral
    stress, height, volume, and each face's stress (the compressive force on a wall over its face)."""
    walls = {name: sim.walls[name] for name in WALLS}
    pos = {name: np.array(w.position) for name, w in walls.items()}
    # the compressive force on a wall: the particles push it against its normal
    push = {name: -float(np.dot(w.force, w.normal)) for name, w in walls.items()}
    lx, ly, lz = (pos[high][k] - pos[low][k] for k, (low, high) in
                  enumerate([("x_low", "x_high"), ("y_low", "y_high"), ("bottom", "top")]))
    area = {"x_low": ly * lz, "x_high": ly * lz, "y_low": lx * lz, "y_high": lx * lz, "bottom": lx * ly,
            "top": lx * ly}
    face = {name: push[name] / area[name] for name in WALLS}
    axial = 0.5 * (face["bottom"] + face["top"])
    lateral = 0.25 * sum(face[name] for name in LATERAL)
    return axial, lateral, lz, lx * ly * lz, face


def triaxial(geometry, folder, size, pressure, rate):
    """One test at this confining pressure (N/mm^2) and axial strain rate (1/ms): the curve, every 50 steps."""
    p = pressure
    # Servo gain: the wall moves at gain x (force error). The loop is stable while gain x k x dt << 1, k the
    # stiffness the wall sees (the specimen's, E A / L ~ 1e6 N/mm here: 0.05 at gain 5e-4), and fast enough for
    # the lateral walls to follow the specimen's bulging in stage 2 (gain 1e-5 let the lateral stress climb 30 %
    # above the target before the peak, 5e-4 holds it within 3 %). max_speed bounds the approach from a gap.
    s = scene(geometry, folder, size, p, gain=5.0e-4, max_speed=0.05)
    rows = []  # (step, time, axial strain, volumetric strain, axial stress, lateral stress, bonds, broken bonds)
    with basalt.Simulation(s) as sim:
        # Stage 1: every wall servoes to the confining pressure; stop once all six faces have been within 2 % of
        # it at 5 checks in a row (250 steps, 0.025 ms: a wave crosses about 9 mm of the specimen in that time).
        tol, held = 0.02, [0]

        def confined(s):
            face = stresses(s)[4]
            held[0] = held[0] + 1 if all(abs(v - p) < tol * p for v in face.values()) else 0
            return held[0] >= 5

        n1 = sim.run(until=confined, every=50, steps=50_000)
        reached = held[0] >= 5
        _, _, h0, v0, face = stresses(sim)
        print(f"p = {p:g}: stage 1, {n1} steps ({sim.time:.3f} ms), faces at "
              + ", ".join(f"{k} {v:.2f}" for k, v in face.items()) + " N/mm^2")

        # Stage 2: the platens close at a constant strain rate (each moves at half of rate x height), the lateral
        # walls go on servoing (a platen given a velocity stops being a servo). The speed is ramped up over 0.25 ms
        # (set_velocity from a callback, every 10 steps), several times the ~0.06 ms a wave takes to cross the
        # specimen: a sudden start would send a stress wave between the platens (the small steps left in the curve
        # are not from the start: docs/python.md).
        speed, ramp_time, t0 = 0.5 * rate * h0, 0.25, sim.time

        def ramp(s):
            f = (s.time - t0) / ramp_time
            if f <= 1.0 + 1e-9:
                s.walls["bottom"].set_velocity((0.0, 0.0, min(f, 1.0) * speed))
                s.walls["top"].set_velocity((0.0, 0.0, -min(f, 1.0) * speed))

        peak = [0.0, 0.0]  # the largest deviatoric stress so far, and its axial strain

        def record(s):  # every 50 steps: one point of the curve (strains positive in compression)
            axial, lateral, lz, volume, _ = stresses(s)
            rows.append((s.step, s.time, (h0 - lz) / h0, (v0 - volume) / v0, axial, lateral, s.bond_count(),
                         s.broken_bonds()))
            if axial - lateral > peak[0]:
                peak[:] = axial - lateral, rows[-1][2]

        def past_peak(s):
            # The deviatoric stress fell below 80 % of a peak reached past 0.05 % of axial strain (the first points
            # wobble about the small stresses of the start), or a strain limit.
            strain, axial, lateral = rows[-1][2], rows[-1][4], rows[-1][5]
            return (peak[1] > 5e-4 and axial - lateral < 0.8 * peak[0]) or strain > 0.02

        sim.callback(ramp, every=10, velocities=False)
        sim.callback(record, every=50, velocities=False)
        n2 = sim.run(until=past_peak, every=50, steps=200_000)
        print(f"p = {p:g}: stage 2, {n2} steps ({rows[-1][1] - rows[0][1]:.3f} ms) to an axial strain of "
              f"{100 * rows[-1][2]:.3f} %")

    # step, time, axial and volumetric strain, axial and lateral stress, deviatoric stress, bonds, broken bonds
    a = np.array([(*r[:6], r[4] - r[5], r[6], r[7]) for r in rows], dtype=float)
    k = int(np.argmax(a[:, 6]))
    print(f"p = {p:g}: peak axial stress {a[k, 4]:.1f} N/mm^2 (deviatoric {a[k, 6]:.1f}) at an axial strain of "
          f"{100 * a[k, 2]:.3f} %, lateral stress {a[k, 5]:.2f} N/mm^2; broken bonds {a[k, 8]:.0f} at the peak, "
          f"{np.nanmax(a[:, 8]):.0f} at the end")
    return {"pressure": p, "reached": reached, "curve": a, "peak": k}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a smaller specimen (the test)")
    ap.add_argument("-o", "--out", type=Path, default=ROOT / "out" / "examples" / "triaxial")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    # The specimen: a box of bonded spheres (the packer bonds touching neighbours), the same for every pressure.
    size = (5.0, 5.0, 10.0) if args.quick else (10.0, 10.0, 20.0)
    rmin, rmax = (0.25, 0.6) if args.quick else (0.2, 0.6)
    geometry = args.out / "specimen.h5"
    g = basalt.pack.box(size=size, rmin=rmin, rmax=rmax, seed=3, output=geometry)
    print(f"specimen {size[0]:g} x {size[1]:g} x {size[2]:g} mm: {g.n_particles} spheres, {g.n_bonds} bonds")
    pressures = (5.0, 20.0) if args.quick else (5.0, 10.0, 20.0)  # N/mm^2
    rate = 5.0e-3 if args.quick else 2.5e-3  # 1/ms: 0.5 % (0.25 %) axial strain per ms
    tests = [triaxial(geometry, args.out / f"run_p{p:g}", size, p, rate) for p in pressures]

    with open(args.out / "stress_strain.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["pressure", "step", "time_ms", "axial_strain", "volumetric_strain", "axial_stress",
                    "lateral_stress", "deviatoric_stress", "bonds_intact", "bonds_broken"])
        for t in tests:
            w.writerows([t["pressure"], int(r[0]), *r[1:7], *(int(x) if np.isfinite(x) else "" for x in r[7:])]
                        for r in t["curve"])

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.6))
    a3 = a2.twinx()
    for i, t in enumerate(tests):
        c, k = t["curve"], t["peak"]
        a1.plot(100 * c[:, 2], c[:, 6], color=f"C{i}", label=f"σ3 = {t['pressure']:g} N/mm²")
        a1.plot(100 * c[k, 2], c[k, 6], "o", color=f"C{i}")
        a2.plot(100 * c[:, 2], c[:, 8], color=f"C{i}")
        a3.plot(100 * c[:, 2], 100 * c[:, 3], ":", color=f"C{i}")
    a1.set_xlabel("axial strain (%)")
    a1.set_ylabel("deviatoric stress σ1 - σ3 (N/mm²)")
    a1.legend(fontsize=8)
    a1.set_title(f"{g.n_particles} bonded spheres, {size[0]:g} x {size[1]:g} x {size[2]:g} mm", fontsize=9)
    a2.set_xlabel("axial strain (%)")
    a2.set_ylabel("broken bonds (solid)")
    a3.set_ylabel("volumetric strain, % (dotted; compression +)")
    fig.tight_layout()
    fig.savefig(args.out / "stress_strain.png", dpi=90)
    print(f"wrote {args.out / 'stress_strain.png'} and {args.out / 'stress_strain.csv'}")

    # The physics the example shows: each pressure was reached; the axial stress rose above it to a peak and fell
    # after it, with bonds broken by then; a higher confining pressure gives a higher axial strength (sigma_1 at
    # the peak; the deviatoric part rises little: bonded-sphere models have a low friction angle).
    failed = []
    for t in tests:
        c, k, p = t["curve"], t["peak"], t["pressure"]
        checks = {"confining pressure reached in stage 1": t["reached"],
                  "lateral stress within 5 % of it at the peak": abs(c[k, 5] - p) < 0.05 * p,
                  "peak axial stress above the confining pressure": c[k, 4] > p,
                  "stress fell after the peak": c[-1, 6] < 0.9 * c[k, 6],
                  "bonds broken after the peak": np.nanmax(c[k:, 8]) > 0}
        failed += [f"p = {p:g}: {name}" for name, ok in checks.items() if not ok]
    strength = [t["curve"][t["peak"], 4] for t in tests]
    if not all(np.diff(strength) > 0):
        failed.append(f"the peak axial stress does not rise with the confining pressure: {strength}")
    for f in failed:
        print(f"FAILED: {f}")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
