"""The wave benchmark from Python, with a callback that records the pulse's arrival: the paper's cube (the GenGeo
cube of tests/data), the base wall moved by a half-sine pulse; every 5 steps a callback reads the vertical
velocities of the particles in thin layers at several heights (numpy views) and keeps their mean; the arrival
at a height is the first time its mean passes 10 % of the pulse's peak. The arrival times against height give
the front's speed (a straight-line fit; in the scene's units, mm/ms = m/s).

    python3 examples/wave_arrival.py            # 1,500 steps (a few seconds)
    python3 examples/wave_arrival.py --quick    # the test: 1,000 steps

Writes out/examples/wave_arrival/arrival.png and arrival.csv.
"""

import argparse
import csv
import tomllib
from pathlib import Path

import numpy as np

import basalt

ROOT = Path(__file__).resolve().parents[1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer steps (the test)")
    ap.add_argument("-o", "--out", type=Path, default=ROOT / "out" / "examples" / "wave_arrival")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    scene = tomllib.loads((ROOT / "scenes" / "wave.toml").read_text())  # the benchmark's physics, as a dict
    scene["geometry"]["file"] = str(ROOT / "tests" / "data" / "cube1.geo")
    scene["output"] = {"directory": str(args.out / "run")}
    steps = 1000 if args.quick else 1500
    heights = np.array([2.0, 4.0, 6.0, 8.0, 10.0, 12.0])  # mm, layers 1 mm thick
    series = []  # (time, mean vz per layer)

    with basalt.Simulation(scene) as sim:
        amplitude = scene["walls"][0]["motion"]["amplitude"]

        def record(s):
            z, vz = s.particles.z, s.particles.vz  # views of this rank's arrays
            means = []
            for h in heights:
                layer = np.abs(z - h) < 0.5
                means.append(s.sum(float(vz[layer].sum())) / max(s.sum(float(layer.sum())), 1.0))
            series.append((s.time, means))

        sim.callback(record, every=5)
        sim.run(steps)

    t = np.array([r[0] for r in series])
    v = np.array([r[1] for r in series])
    arrival = []
    for k, h in enumerate(heights):
        above = np.nonzero(v[:, k] > 0.1 * amplitude)[0]
        arrival.append(t[above[0]] if len(above) else np.nan)
    arrival = np.array(arrival)
    ok = np.isfinite(arrival)
    speed = np.polyfit(arrival[ok], heights[ok], 1)[0] if ok.sum() >= 2 else np.nan
    with open(args.out / "arrival.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["height_mm", "arrival_ms"])
        w.writerows(zip(heights, arrival))
    print("arrival (ms) at heights (mm):", ", ".join(f"{h:g}: {a:.3f}" for h, a in zip(heights, arrival)))
    print(f"front speed from the fit: {speed:.2f} mm/ms")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.5))
    for k, h in enumerate(heights):
        a1.plot(t, v[:, k], label=f"z = {h:g} mm")
    a1.set_xlabel("time (ms)")
    a1.set_ylabel("mean vz of the layer (mm/ms)")
    a1.legend(fontsize=7)
    a2.plot(arrival, heights, "o")
    if np.isfinite(speed):
        tt = np.linspace(np.nanmin(arrival), np.nanmax(arrival), 2)
        b = np.polyfit(arrival[ok], heights[ok], 1)
        a2.plot(tt, np.polyval(b, tt), "-", label=f"{speed:.1f} mm/ms")
        a2.legend()
    a2.set_xlabel("arrival (ms)")
    a2.set_ylabel("height (mm)")
    fig.tight_layout()
    fig.savefig(args.out / "arrival.png", dpi=120)
    print(f"wrote {args.out / 'arrival.png'} and {args.out / 'arrival.csv'}")
    # The physics the example shows: the front climbs (arrivals increase with height) at a finite speed.
    return 0 if ok.sum() >= 3 and np.all(np.diff(arrival[ok]) > 0) and speed > 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
