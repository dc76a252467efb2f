#!/usr/bin/python3
"""Start-up time (reading the geometry to the first step) and peak memory per rank of basalt-run, with the
geometry read in slices (the default) against every rank reading the whole file (--whole-geometry, the former
start-up; or another basalt-run build with --baseline-run), interleaved, median of --repeats
(docs/BENCHMARKS.md, "Start-up").

    /usr/bin/python3 tools/bench/startup_bench.py --np 2 --repeats 3 cube1.h5 cube30.h5 cube60.h5

Each geometry must be .h5 (convert a .geo with basalt-view convert, or let basalt-run convert it once).
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("geometries", nargs="+")
ap.add_argument("--np", type=int, default=2)
ap.add_argument("--repeats", type=int, default=3)
ap.add_argument("--run", default=bt.binary("basalt-run"))
ap.add_argument("--baseline-run", help="another basalt-run (e.g. a build of an older commit) to time as well")
ap.add_argument("--scene", default=bt.repo_path("scenes", "wave.toml"))
a = ap.parse_args()

variants = [("sliced", a.run, []), ("whole", a.run, ["--whole-geometry"])]
if a.baseline_run:
    variants.append(("baseline", a.baseline_run, []))


def once(run, extra, geometry, out):
    cmd = bt.mpirun(a.np) + ["/usr/bin/time", "-f", "maxrss_kb %M", run, a.scene, "--geometry", geometry,
           "--steps", "1", "--fields-every", "0", "--quiet", "--output", out] + extra
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stdout}\n{p.stderr}")
    r = bt.parse_run(p.stdout)
    rss = max(int(v) for v in re.findall(r"maxrss_kb (\d+)", p.stderr))
    return r["startup_s"], rss, r["particles"]


print(f"| geometry | particles | " + " | ".join(f"{v[0]}: start-up s, max RSS/rank MB" for v in variants) +
      " | sliced / whole |")
print("| --- | ---: | " + " | ".join("---" for _ in variants) + " | ---: |")
with tempfile.TemporaryDirectory() as tmp:
    for g in a.geometries:
        res = {v[0]: [] for v in variants}
        n = 0
        for _ in range(a.repeats):
            for name, run, extra in variants:
                s, rss, n = once(run, extra, g, os.path.join(tmp, name))
                res[name].append((s, rss))
        med = {k: (statistics.median(x[0] for x in v), max(x[1] for x in v) / 1024) for k, v in res.items()}
        cells = " | ".join(f"{med[k][0]:.3f}, {med[k][1]:.0f}" for k, _, _ in variants)
        print(f"| {os.path.basename(g)} | {n:,} | {cells} | {med['sliced'][0] / med['whole'][0]:.2f} |", flush=True)
