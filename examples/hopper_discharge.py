"""Hopper (silo) discharge with insertion and deletion, from Python, against Beverloo's law: a flat-bottomed
cylindrical silo (a triangle-mesh wall, tools/mesh/make_silo.py) with a central orifice closed by a planar gate
is filled by pouring handfuls of glass beads in at the top (sim.insert), the fill settles, the gate is taken away
(sim.walls["gate"].remove()) and the grains that fall out are taken out below the silo by the scene's [[delete]].
The discharge rate W (mass per time) is the slope of the discharged mass against time over the steady part;
Beverloo: W = C rho_b sqrt(g) (D0 - k d)^(5/2), rho_b the settled fill's measured bulk density. Units: mm, ms, N
(g for masses). One rank.

    python3 examples/hopper_discharge.py            # three orifices in a 28 mm silo (~2,500 grains each)
    python3 examples/hopper_discharge.py --quick    # the test: one orifice in a smaller silo (< 1 min)

Writes out/examples/hopper_discharge/discharge.csv (per orifice and every 50 steps of the discharge: time after
the gate opened, grains discharged, discharged mass) and discharge.png (discharged mass against time per orifice,
and W against D0 with Beverloo's curve), and prints each orifice's fill, rate and ratio to Beverloo's law.
The discharged mass is the fill's mass minus the mass still in the run (sim.sum of the particles' masses), the
grains discharged sim.deleted; the script fails unless the fill reached its target count with unique ids, the
particle count balances (initial + inserted - deleted), grains flow out at a steady rate (R^2 > 0.95 of a
straight line) and each W is within a factor 2 of Beverloo's law with C = 0.58, k = 1.5.
"""

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

import basalt

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools" / "mesh"))
from make_silo import silo_triangles, write_stl  # noqa: E402  (tools/mesh/make_silo.py)

RMIN, RMAX = 0.9, 1.1          # grain radii (mm): d = 2 mm
D = RMIN + RMAX                 # mean diameter
DENSITY = 2.5e-3                # g/mm^3 (glass)
G = 9.81e-3                     # mm/ms^2
K = 1.0                         # N/mm, normal contact stiffness (grains and walls)
C_LIT, K_LIT = 0.58, 1.5        # Beverloo's constants from the literature (C 0.55-0.65, k 1.3-2.9)
FIELD_EVERY = 50                # steps between two records of the discharge


def grain_mass(r):
    return DENSITY * 4.0 / 3.0 * np.pi * np.asarray(r) ** 3


def dt():
    """0.15 of the one-contact critical step 2 sqrt(m_min / K) of the lightest grain."""
    return 0.15 * 2.0 * np.sqrt(grain_mass(RMIN) / K)


def beverloo(d0, rho_b, c=C_LIT, k=K_LIT):
    return c * rho_b * np.sqrt(G) * np.clip(np.asarray(d0, dtype=float) - k * D, 0.0, None) ** 2.5


def silo_mesh(folder, diameter, height, orifice):
    """The silo as an STL, written with tools/mesh/make_silo.py's own functions."""
    path = folder / f"silo_d{diameter:g}_o{orifice:g}.stl"
    with open(path, "w") as f:
        write_stl(silo_triangles(diameter, height, orifice, 64), f, path.stem)
    return path


def scene(geometry, mesh, out, radius, height):
    """Frictional rotating glass beads (scenes/hopper.toml's models) in the mesh silo, a frictional gate under the
    orifice, gravity and Cundall's local damping (for the fill; switched off for the discharge). The [[insert]]
    entry has count = 0 (no events of its own): it declares the radii the script pours (the contact reach
    and the critical step count them) and widens the decomposition's box to the silo. The [[delete]] takes out
    every grain 3 d below the silo's floor every 50 steps."""
    friction = {"K": K, "Ks": 0.5 * K, "mu": 0.5, "mu_dynamic": 0.4}
    return {
        "units": {"length": "mm", "time": "ms", "force": "N"},
        "geometry": {"file": str(geometry)},
        "material": {"density": DENSITY},
        "particles": {"rotation": True},
        "run": {"dt": float(dt()), "skin": 0.2},
        "interactions": [{"name": "grains", "type": "rot_friction", **friction}],
        "mesh_walls": [{"name": "silo", "file": str(mesh), "sides": "two", "interaction": "friction", **friction}],
        "walls": [{"name": "gate", "point": [0.0, 0.0, -0.05], "normal": [0.0, 0.0, 1.0], "interaction": "friction",
                   **friction}],
        "body_forces": [{"name": "gravity", "type": "gravity", "acceleration": [0.0, 0.0, -G]},
                        {"name": "damping", "type": "local_damping", "alpha": 0.3}],
        "insert": [{"name": "reach", "cylinder": {"base": [0.0, 0.0, 0.0], "axis": [0.0, 0.0, 1.0],
                                                  "radius": float(radius), "length": float(height)},
                    "radius": [RMIN, RMAX], "count": 0}],
        "delete": [{"name": "outlet", "box": {"min": [-10 * radius, -10 * radius, -1.0e4],
                                              "max": [10 * radius, 10 * radius, -3.0 * D]}, "every": FIELD_EVERY}],
        "output": {"directory": str(out)},
    }


def total_mass(sim):
    return sim.sum(float(np.sum(1.0 / sim.particles.inv_mass)))


def fit_line(t, y):
    """Least-squares y = a + b t: (b, a, R^2)."""
    b, a = np.polyfit(t, y, 1)
    res = y - (a + b * t)
    r2 = 1.0 - float(np.sum(res**2)) / float(np.sum((y - y.mean()) ** 2))
    return float(b), float(a), r2


def hopper(folder, diameter, orifice, fill_height, discharge_fraction, seed=1):
    """One silo: fill, settle, discharge; returns what was measured."""
    R = diameter / 2.0
    height = fill_height + 14.0                      # room above the fill for the pour
    mesh = silo_mesh(folder, diameter, height, orifice)
    # The run starts from a thin bed (two grains deep) packed on the silo's floor; the rest is poured.
    bed = basalt.pack.cylinder(radius=R - 0.1, height=2 * D, origin=(0, 0, 0), rmin=RMIN, rmax=RMAX, seed=seed,
                               no_bonds=True, allow_low_fraction=True, threads=1)
    geometry = folder / f"bed_d{diameter:g}_o{orifice:g}.h5"
    bed.write(geometry)
    # Target: the grains that fill the silo to fill_height at a solid fraction of 0.6.
    mean_volume = 4.0 / 3.0 * np.pi * (RMAX**4 - RMIN**4) / (4 * (RMAX - RMIN))
    target = int(0.6 * np.pi * R**2 * fill_height / mean_volume)
    t0, c0 = time.perf_counter(), time.process_time()
    with basalt.Simulation(scene(geometry, mesh, folder / f"run_d{diameter:g}_o{orifice:g}", R - 0.2, height)) as sim:
        initial = sim.total_particles
        # Stage 1: pour handfuls at the top until the target count is in.
        pour = dict(base=(0.0, 0.0, fill_height + 4.0), axis=(0.0, 0.0, 1.0), radius=R - 1.2, length=8.0)
        k, fill_steps = 0, 0
        while sim.total_particles < target:
            k += 1
            sim.insert(cylinder=pour, radius=(RMIN, RMAX), count=min(80, target - sim.total_particles),
                       velocity=(0.0, 0.0, -0.3), tag=1, seed=seed * 1000 + k)
            fill_steps += sim.run(300)
            if k > 2000:
                raise RuntimeError(f"the pour did not reach {target} grains ({sim.total_particles})")
        filled = sim.total_particles
        ids = sim.gather("id")[0]
        unique = len(np.unique(ids)) == len(ids) == filled
        # Stage 2: settle until the grains are nearly at rest (mean speed ~ 3e-3 mm/ms).
        n = filled
        m_grain = float(grain_mass(0.5 * (RMIN + RMAX)))
        settle = sim.run(until=lambda s: s.kinetic_energy() / n < 0.5 * m_grain * 1e-5, every=200, steps=40000)
        # The settled fill's bulk density: the grains whose centre lies in a slab away from floor and surface.
        _, z = sim.gather("z")
        _, r = sim.gather("radius")
        top = float(np.percentile(z, 99))
        lo, hi = 2 * D, top - 2 * D
        inside = (z > lo) & (z < hi)
        phi = float(np.sum(4.0 / 3.0 * np.pi * r[inside] ** 3) / (np.pi * R**2 * (hi - lo)))
        rho_b = phi * DENSITY
        # Stage 3: no damping; open the orifice; record the discharge until discharge_fraction of the fill is out.
        sim.set_body_force("damping", alpha=0.0)
        m0 = total_mass(sim)
        deleted0 = sim.deleted
        sim.walls["gate"].remove()
        opened, rows = sim.time, []

        def record(s):
            out = m0 - total_mass(s)
            rows.append((s.time - opened, s.deleted - deleted0, out))
            stalled = len(rows) > 400 and rows[-1][1] == rows[-401][1]   # nothing out for 400 records: jammed
            return not (out >= discharge_fraction * m0 or stalled)

        sim.callback(record, every=FIELD_EVERY, velocities=False)
        discharge_steps = sim.run(2_000_000)
        balance = sim.total_particles == initial + sim.inserted - sim.deleted
        elapsed, cpu = time.perf_counter() - t0, time.process_time() - c0
    t, count, mass = (np.array(c, dtype=float) for c in zip(*rows))
    # The steady part: from 15 % of the mass discharged in the end to 90 % of it (none when the orifice jammed
    # before 50 grains were out: an arch across it, likely below D0 ~ 4-5 d).
    steady = (mass >= 0.15 * mass[-1]) & (mass <= 0.9 * mass[-1])
    jammed = count[-1] < 50
    if jammed:
        steady[:] = False
        W = rate = r2_mass = r2_count = float("nan")
    else:
        W, _, r2_mass = fit_line(t[steady], mass[steady])
        rate, _, r2_count = fit_line(t[steady], count[steady])
    return {"diameter": diameter, "orifice": orifice, "initial": initial, "target": target, "filled": filled,
            "unique_ids": unique, "handfuls": k, "fill_steps": fill_steps, "settle_steps": settle, "phi": phi,
            "rho_b": rho_b, "fill_top": top, "fill_mass": m0, "discharge_steps": discharge_steps,
            "discharged": int(count[-1]), "discharged_mass": float(mass[-1]), "balance": balance,
            "W": W, "grains_per_ms": rate, "r2": min(r2_mass, r2_count), "jammed": jammed,
            "window": (t[steady][0], t[steady][-1]) if steady.any() else (float("nan"),) * 2,
            "t": t, "count": count, "mass": mass, "seconds": elapsed, "cpu_seconds": cpu,
            "discharge_fraction": discharge_fraction,
            "beverloo": float(beverloo(orifice, rho_b))}


def fit_beverloo(results):
    """C with k = 1.5 (one parameter, any number of orifices), and C, k together from W^(2/5) linear in D0 (three
    or more orifices): W^(2/5) = (C rho_b sqrt g)^(2/5) (D0 - k d)."""
    rho_b = float(np.mean([r["rho_b"] for r in results]))
    results = [r for r in results if not r["jammed"]]
    if not results:
        return rho_b, float("nan"), None, None
    d0 = np.array([r["orifice"] for r in results])
    w = np.array([r["W"] for r in results])
    shape = (d0 - K_LIT * D) ** 2.5
    c_fixed = float(np.sum(w * shape) / np.sum(shape**2)) / (rho_b * np.sqrt(G))
    c_fit = k_fit = None
    if len(results) >= 3:
        slope, intercept = np.polyfit(d0, w**0.4, 1)
        k_fit = float(-intercept / slope / D)
        c_fit = float(slope**2.5 / (rho_b * np.sqrt(G)))
    return rho_b, c_fixed, c_fit, k_fit


def plot(results, fit, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rho_b, c_fixed, c_fit, k_fit = fit
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.6))
    for r in results:
        if r["jammed"]:
            continue
        a1.plot(r["t"], r["mass"], lw=1.2, label=f"D0 = {r['orifice']:g} mm ({r['orifice'] / D:.2g} d)")
        t0, t1 = r["window"]
        tt = np.array([t0, t1])
        b = np.polyfit(r["t"][(r["t"] >= t0) & (r["t"] <= t1)], r["mass"][(r["t"] >= t0) & (r["t"] <= t1)], 1)
        a1.plot(tt, np.polyval(b, tt), "k--", lw=0.8)
    a1.set_xlabel("time after the gate opened (ms)")
    a1.set_ylabel("discharged mass (g)")
    a1.legend(fontsize=8)
    d0 = np.array([r["orifice"] for r in results])
    a2.plot(d0, [r["W"] * 1e3 for r in results], "o", label="measured (steady part)")
    x = np.linspace(min(d0.min(), K_LIT * D + 0.5) - 0.5, d0.max() + 1.0, 100)
    a2.plot(x, beverloo(x, rho_b) * 1e3, "-", label=f"Beverloo C = {C_LIT}, k = {K_LIT}")
    a2.plot(x, beverloo(x, rho_b, c=c_fixed) * 1e3, "--", label=f"fit, k = {K_LIT}: C = {c_fixed:.2f}")
    if c_fit is not None:
        a2.plot(x, beverloo(x, rho_b, c=c_fit, k=k_fit) * 1e3, ":", label=f"fit: C = {c_fit:.2f}, k = {k_fit:.2f}")
    a2.set_xlabel("orifice D0 (mm); d = 2 mm")
    a2.set_ylabel("discharge rate W (mg/ms)")
    a2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one small silo (the test)")
    ap.add_argument("-o", "--out", type=Path, default=ROOT / "out" / "examples" / "hopper_discharge")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.quick:
        cases = [dict(diameter=18.0, orifice=9.0, fill_height=14.0, discharge_fraction=0.5)]
    else:
        cases = [dict(diameter=28.0, orifice=o, fill_height=29.0, discharge_fraction=0.3) for o in (8.0, 9.5, 11.0)]
    results = []
    for c in cases:
        results.append(hopper(args.out, **c))
        print(f"D0 = {c['orifice']:g} mm: {results[-1]['discharged']} grains out, "
              f"W = {results[-1]['W'] * 1e3:.3f} mg/ms, {results[-1]['seconds']:.0f} s "
              f"({results[-1]['cpu_seconds']:.0f} s of CPU)", flush=True)
    fit = fit_beverloo(results)
    with open(args.out / "discharge.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["orifice_mm", "time_ms", "discharged_count", "discharged_mass_g"])
        for r in results:
            for t, n, m in zip(r["t"], r["count"], r["mass"]):
                w.writerow([r["orifice"], f"{t:.6g}", int(n), f"{m:.6g}"])
    ok = True
    for r in results:
        ratio = r["W"] / r["beverloo"]
        print(f"silo {r['diameter']:g} mm, D0 = {r['orifice']:g} mm (D0/d = {r['orifice'] / D:.2f}): "
              f"{r['initial']} + {r['filled'] - r['initial']} poured = {r['filled']} grains (target {r['target']}, "
              f"{r['handfuls']} handfuls, {r['fill_steps']} steps), settled in {r['settle_steps']} steps to "
              f"z = {r['fill_top']:.1f} mm, solid fraction {r['phi']:.3f}; {r['discharged']} grains "
              f"({r['discharged_mass']:.3f} g) out in {r['discharge_steps']} steps; "
              f"W = {r['W'] * 1e3:.3f} mg/ms ({r['grains_per_ms']:.3f} grains/ms, R^2 {r['r2']:.4f}, "
              f"t = {r['window'][0]:.0f}-{r['window'][1]:.0f} ms), Beverloo {r['beverloo'] * 1e3:.3f} mg/ms, "
              f"ratio {ratio:.2f}; {r['seconds']:.1f} s ({r['cpu_seconds']:.1f} s of CPU)"
              + (" (JAMMED: an arch closed the orifice)" if r["jammed"] else ""))
        checks = {"fill reached its target with unique ids": r["filled"] == r["target"] and r["unique_ids"],
                  "initial + inserted - deleted == total": r["balance"],
                  "grains discharged (no jam)": r["discharged_mass"] >= r["discharge_fraction"] * r["fill_mass"],
                  "steady rate (R^2 > 0.95)": r["r2"] > 0.95,
                  "W within a factor 2 of Beverloo (C 0.58, k 1.5)": 0.5 < ratio < 2.0}
        for name, passed in checks.items():
            if not passed:
                print(f"FAILED: {name}")
                ok = False
    rho_b, c_fixed, c_fit, k_fit = fit
    print(f"Beverloo fit (rho_b = {rho_b:.3g} g/mm^3 measured): C = {c_fixed:.3f} with k = {K_LIT}"
          + (f"; C = {c_fit:.3f}, k = {k_fit:.2f} together" if c_fit is not None else ""))
    plot(results, fit, args.out / "discharge.png")
    print(f"wrote {args.out / 'discharge.png'} and {args.out / 'discharge.csv'}")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
