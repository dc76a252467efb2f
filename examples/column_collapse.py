"""Column collapse in stages, from Python: pack a column behind a gate, let it settle under gravity until its
kinetic energy is small, take the gate away, let it run out; the runout against the column's aspect ratio.

    python3 examples/column_collapse.py                 # aspect ratios 0.5, 1, 2 (200-300 grains each, ~5 s)
    python3 examples/column_collapse.py --quick         # two smaller columns (the test)

Writes out/examples/column_collapse/runout.png and runout.csv (aspect ratio, height, width, final runout).
Runout: the distance from the back wall reached by the 99th percentile of the grains, over the initial width.
"""

import argparse
import csv
import tomllib
from pathlib import Path

import numpy as np

import basalt

ROOT = Path(__file__).resolve().parents[1]


def column(folder, width, height, depth, seed):
    """A column of unbonded spheres (radius 0.4-0.6, as the scene's) packed in [0,width]x[0,depth]x[0,height] (a
    narrow column packs looser than the packer's target near its walls: allowed)."""
    path = folder / f"column_{width:g}x{height:g}.h5"
    basalt.pack.box(size=(width, depth, height), rmin=0.4, rmax=0.6, seed=seed, no_bonds=True,
                    allow_low_fraction=True).write(path)
    return path


def scene(geometry, out, width, depth):
    """The project's column-collapse scene (scenes/column-collapse.toml: frictional rotating grains, a frictional
    floor, a back wall, side walls, damping), read as a dict and changed here: this column, no run.steps (the
    script says how long), and a gate wall at x = width that holds the column until stage 2."""
    s = tomllib.loads((ROOT / "scenes" / "column-collapse.toml").read_text())
    s["geometry"]["file"] = str(geometry)
    s["output"] = {"directory": str(out)}
    del s["run"]["steps"]
    for w in s["walls"]:
        if w["name"] == "side_yW":
            w["point"] = [0.0, float(depth), 0.0]
    s["walls"].append({"name": "gate", "point": [float(width), 0.0, 0.0], "normal": [-1.0, 0.0, 0.0], "K": 2000.0})
    return s


def collapse(folder, width, height, depth, seed=3):
    geometry = column(folder, width, height, depth, seed)
    with basalt.Simulation(scene(geometry, folder / f"run_{width:g}x{height:g}", width, depth)) as sim:
        n = sim.total_particles
        # Stage 1: settle behind the gate until the kinetic energy per grain is small.
        settle = sim.run(until=lambda s: s.kinetic_energy() / n < 1e-5, every=200, steps=40000)
        # Stage 2: take the gate away and let the column run out until it stops.
        sim.walls["gate"].remove()
        opened, front = sim.time, []

        def watch(s):  # every 200 steps: record the front; end the run once the flow has stopped
            front.append((s.time - opened, s.max(float(np.percentile(s.particles.x, 99)))))
            return not (len(front) > 20 and front[-1][1] - front[-21][1] < 0.01)  # < 1 % of a grain in 20 checks

        sim.callback(watch, every=200)
        out = sim.run(60000)
        final = sim.max(float(np.percentile(sim.particles.x, 99)))
        return {"aspect": height / width, "height": height, "width": width, "particles": n, "settle_steps": settle,
                "runout_steps": out, "runout": (final - width) / width, "front": front}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="two small columns (the test)")
    ap.add_argument("-o", "--out", type=Path, default=ROOT / "out" / "examples" / "column_collapse")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    shapes = [(6, 3), (4, 6)] if args.quick else [(10, 5), (8, 8), (6, 12)]
    depth = 4 if args.quick else 6
    results = [collapse(args.out, w, h, depth) for w, h in shapes]
    with open(args.out / "runout.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["aspect", "height", "width", "particles", "settle_steps", "runout_steps", "runout"])
        for r in results:
            w.writerow([r["aspect"], r["height"], r["width"], r["particles"], r["settle_steps"], r["runout_steps"],
                        r["runout"]])
            print(f"a = {r['aspect']:.2f}: {r['particles']} grains, settled in {r['settle_steps']} steps, "
                  f"runout (L - L0) / L0 = {r['runout']:.3f} after {r['runout_steps']} steps")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.5))
    a1.plot([r["aspect"] for r in results], [r["runout"] for r in results], "o-")
    a1.set_xlabel("aspect ratio H / L0")
    a1.set_ylabel("runout (L - L0) / L0")
    for r in results:
        t, x = zip(*r["front"]) if r["front"] else ([], [])
        a2.plot(t, x, label=f"a = {r['aspect']:.2f}")
    a2.set_xlabel("time after the gate opened")
    a2.set_ylabel("front (99th percentile x)")
    a2.legend()
    fig.tight_layout()
    fig.savefig(args.out / "runout.png", dpi=120)
    print(f"wrote {args.out / 'runout.png'} and {args.out / 'runout.csv'}")
    # The physics the example shows: a taller column runs out farther.
    taller = sorted(results, key=lambda r: r["aspect"])
    return 0 if taller[-1]["runout"] > taller[0]["runout"] > 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
