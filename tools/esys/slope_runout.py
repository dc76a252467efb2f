"""The quantities a slope-failure run is judged by, from its ESyS text checkpoints (ESyS-Particle's own or Basalt's
ESyS front end's, docs/esys.md "Compared with ESyS-Particle"): the particles left in the spatial domain, their mean
height (y) and the runout (the 95th percentile and the largest horizontal distance sqrt(x^2 + z^2) from the
block's axis), at a given step.

    /usr/bin/python3 tools/esys/slope_runout.py --step 50000 --prefix slope_data esys/ esys_nudged/ basalt/ ...

The tutorial's slope_fail.py writes slope_data_t=STEP_1.txt every 1,000 steps. Its spread against itself is
measured by running it twice per code, the second time with the floor moved by 1e-9 along y
(`posn = Vec3(0.0000, 1.0e-9, 0.0000)` in the script's createWall), in folders of their own:
    mpirun -np 2 esysparticle slope_fail.py          # ESyS-Particle
    python3 -m basalt.esys slope_fail.py             # Basalt's front end
"""

import argparse
import math


def quantities(path):
    with open(path) as f:
        lines = f.read().splitlines()
    n = int(lines[0])
    rows = [[float(v) for v in line.split()[:3]] for line in lines[1:1 + n]]
    heights = [y for _, y, _ in rows]
    radial = sorted(math.hypot(x, z) for x, _, z in rows)
    p95 = radial[min(len(radial) - 1, int(math.ceil(0.95 * len(radial))) - 1)] if radial else float("nan")
    return {"particles": n, "mean height": sum(heights) / n if n else float("nan"), "runout p95": p95,
            "runout max": radial[-1] if radial else float("nan")}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("folders", nargs="+", help="run folders holding PREFIX_t=STEP_1.txt")
    ap.add_argument("--step", type=int, required=True)
    ap.add_argument("--prefix", default="slope_data")
    args = ap.parse_args()
    table = [(d, quantities(f"{d.rstrip('/')}/{args.prefix}_t={args.step}_1.txt")) for d in args.folders]
    names = list(table[0][1])
    print("| run | " + " | ".join(names) + " |")
    print("| --- |" + " ---: |" * len(names))
    for d, q in table:
        print(f"| {d} | " + " | ".join(f"{q[k]:.6g}" for k in names) + " |")


if __name__ == "__main__":
    main()
