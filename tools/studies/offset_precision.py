#!/usr/bin/env python3
"""Kinetic-energy error of the wave scene when every coordinate (and the wall) is shifted by D, in double
and in float, against the unshifted double run (docs/stability.md, "Coordinates far from the origin").

    /usr/bin/python3 tools/studies/offset_precision.py --build build --geometry $BASALT_REFERENCE_DIR/cube1.geo \
        [--steps 2000] [--work offset-work] [--scale S] [--precisions double,mixed] [--offsets 1e6,1e9]

--scale S multiplies every coordinate and radius first (S = 2.5: cube1's smallest radius 0.2 becomes 0.5;
the wall's half-sine, 0.1, is then a smaller strain of the larger cube). Prints one row per (precision, D):
L2 and max relative KE error, or basalt-run's last error line when it refuses or stops the run, and its
first warning when it warns.
"""
import argparse
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

ROOT = Path(bt.ROOT)


def shifted_geo(lines, d, out, scale=1.0):
    i0 = lines.index("Simple") + 2
    n = int(lines[i0 - 1])
    res = list(lines)
    for k, line in enumerate(res):
        if line.startswith("BoundingBox"):
            res[k] = "BoundingBox " + " ".join("%.17g" % (float(x) * scale + d) for x in line.split()[1:])
    for k in range(i0, i0 + n):
        p = res[k].split()
        res[k] = " ".join(["%.17g" % (float(p[j]) * scale + d) for j in range(3)] +
                          ["%.17g" % (float(p[3]) * scale)] + p[4:])
    out.write_text("\n".join(res))


def run(a, work, lines, d, precision):
    g, s, o = work / f"g{d:g}.geo", work / f"s{d:g}.toml", work / f"o_{d:g}_{precision}"
    shifted_geo(lines, d, g, a.scale)
    scene = (ROOT / "scenes" / "wave.toml").read_text()
    s.write_text(scene.replace("point = [0.0, 0.0, 0.0]", f"point = [{d:.17g}, {d:.17g}, {d:.17g}]"))
    r = subprocess.run([bt.binary("basalt-run", build=a.build), str(s), "--geometry", str(g), "--steps",
                        str(a.steps), "--output", str(o), "--quiet", "--precision", precision],
                       capture_output=True, text=True)
    if r.returncode:
        return None, r.stderr.strip().split("\n")[-1][:160]
    warn = [w for w in r.stderr.split("\n") if "warning" in w]
    return np.array(bt.read_fields(o)["kinetic_energy"]), (warn[0][:200] if warn else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--geometry", required=True)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--work", default="offset-work")
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--precisions", default="double,float")
    ap.add_argument("--offsets", default="", help="comma-separated D (default: per precision, below)")
    a = ap.parse_args()
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    lines = Path(a.geometry).read_text().split("\n")
    ref, msg = run(a, work, lines, 0.0, "double")
    if ref is None:
        raise SystemExit(f"the unshifted run failed: {msg}")
    print("| precision | D | KE L2 relative | KE max relative | basalt-run said |")
    print("| --- | --- | --- | --- | --- |")
    default = {"double": [1e3, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12], "float": [0, 10, 100, 1e3, 1e4],
               "mixed": [0, 1e6, 1e9, 1e12]}
    for precision in a.precisions.split(","):
        offsets = [float(x) for x in a.offsets.split(",")] if a.offsets else default[precision]
        for d in offsets:
            ke, msg = run(a, work, lines, float(d), precision)
            if ke is None:
                print(f"| {precision} | {d:g} | | | {msg} |", flush=True)
                continue
            m = min(len(ke), len(ref))
            l2 = np.sqrt(np.sum((ke[:m] - ref[:m]) ** 2) / np.sum(ref[:m] ** 2))
            mx = np.max(np.abs(ke[:m] - ref[:m])) / np.max(ref[:m])
            print(f"| {precision} | {d:g} | {l2:.2e} | {mx:.2e} | {msg} |", flush=True)


if __name__ == "__main__":
    main()
