#!/usr/bin/python3
"""basalt-pack against GenGeo, side by side in one run (docs/packer.md, "Benchmark").

Packs the seed paper's base cube (15 mm, radii 0.2-1.0, overlap tolerance 1e-6, bonds within 1e-5) with
GenGeo (python3-gengeo: InsertGenerator3D insertFails 1000, maxIterations 1000) and with basalt-pack,
alternating, `--repeats` times each, and reports medians and the ratio. With --large it also packs about
1 M spheres and the paper's largest assembly (150 mm cube) once each under /usr/bin/time -v (wall time,
peak RSS). Writes a markdown table to --out (default docs/bench/packer.md).

Usage: /usr/bin/python3 tools/bench/pack_benchmark.py [--basalt-pack build/bin/basalt-pack]
                                                     [--repeats 5] [--large] [--out docs/bench/packer.md]
"""
import argparse
import datetime
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

ROOT = bt.ROOT


def run_timed(cmd):
    """Runs cmd under /usr/bin/time -v; returns (stdout, wall seconds, peak RSS in MiB, user seconds)."""
    p = bt.run(cmd, timed=True, check=False)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stdout}\n{p.stderr}")
    return p.stdout, p.time["wall_s"], p.time["max_rss_kb"] / 1024, p.time["user_s"]


def basalt(exe, args, out):
    stdout, wall, rss, user = run_timed([exe] + args + ["-o", out])
    num = lambda key: float(re.search(key + r"\s+([-0-9.e+]+)", stdout).group(1))
    t = re.search(r"time\s+([0-9.]+) s \(([0-9.]+) s packing\)", stdout)
    return {"particles": int(num("particles")), "solid_fraction": num("solid fraction"),
            "exponent": num("fitted exponent"), "bonds": int(num("bonds")),
            "coordination": num("mean coordination"), "overlap": num("largest overlap"),
            "seconds": float(t.group(1)), "wall": wall, "rss_mib": rss, "user": user}


def gengeo(out):
    stdout, wall, rss, user = run_timed(["/usr/bin/python3", os.path.join(HERE, "gengeo_cube.py"),
                                         "15", "0.2", "1.0", out])
    r = json.loads(stdout.strip().splitlines()[-1])
    r.update({"wall": wall, "rss_mib": rss, "user": user})
    return r


def med(rows, key):
    return statistics.median(r[key] for r in rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--basalt-pack", default=bt.binary("basalt-pack"))
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--large", action="store_true", help="also the ~1 M and the 150 mm (~8.7 M) packs")
    ap.add_argument("--large-only", action="store_true", help="only the large packs")
    ap.add_argument("--large-cases", default="1m,150-dense,8.7m",
                    help="which large packs (rows of other cases already in packer-large.md are kept)")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "bench"),
                    help="folder for packer-cube.md (side by side) and packer-large.md (--large)")
    ap.add_argument("--doc", default=os.path.join(ROOT, "docs", "packer.md"),
                    help="document whose bench:cube / bench:large sections are replaced ('' for none)")
    a = ap.parse_args()
    exe = os.path.abspath(a.basalt_pack)
    tmp = tempfile.mkdtemp(prefix="basalt-pack-bench-")
    cube = ["box", "--size", "15,15,15", "--rmin", "0.2", "--rmax", "1.0", "--overlap-tolerance", "1e-6",
            "--bond-tolerance", "1e-5"]
    genlike = ["--exponent", "2.2", "--target-fraction", "0.62", "--fill"]
    have_gengeo = subprocess.run(["/usr/bin/python3", "-c", "import gengeo"], capture_output=True).returncode == 0
    gg, bp, bl = [], [], []
    for i in range(0 if a.large_only else a.repeats):
        seed = str(i + 1)
        if have_gengeo:
            gg.append(gengeo(os.path.join(tmp, "gengeo.geo")))
        bp.append(basalt(exe, cube + ["--seed", seed], os.path.join(tmp, "dense.geo")))
        bl.append(basalt(exe, cube + genlike + ["--seed", seed], os.path.join(tmp, "genlike.geo")))
        print(f"repeat {i + 1}: GenGeo {gg[-1]['seconds'] if gg else float('nan'):.2f} s, "
              f"basalt-pack {bp[-1]['seconds']:.3f} s / {bl[-1]['seconds']:.3f} s", flush=True)
    # Stored statistics need particles and seconds only; wall includes process start and file writing.
    large = []
    if a.large or a.large_only:
        cases = {
            "1m": ("~1 M spheres: 90 mm cube, dense", ["box", "--size", "90,90,90", "--rmin", "0.2", "--rmax", "1.0"]),
            "150-dense": ("150 mm cube, dense", ["box", "--size", "150,150,150", "--rmin", "0.2", "--rmax", "1.0"]),
            "8.7m": ("~8.7 M spheres (the paper's largest count): 180 mm cube, dense",
                     ["box", "--size", "180,180,180", "--rmin", "0.2", "--rmax", "1.0"]),
            "150-genlike": ("paper's largest: 150 mm cube, GenGeo-like (`--exponent 2.2 --target-fraction 0.62 --fill`)",
                            ["box", "--size", "150,150,150", "--rmin", "0.2", "--rmax", "1.0"] + genlike)}
        for key in a.large_cases.split(","):
            label, args = cases[key]
            r = basalt(exe, args + ["--seed", "1"], os.path.join(tmp, "large.geo"))
            r["label"] = label
            large.append(r)
            print(f"{label}: {r['particles']} spheres, {r['seconds']:.1f} s, {r['rss_mib']:.0f} MiB", flush=True)
    shutil.rmtree(tmp, ignore_errors=True)

    os.makedirs(a.out, exist_ok=True)
    stamp = (f"Measured {datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC on {platform.node()} "
      f"({os.cpu_count()} cores, shared with other work: load average "
      f"{os.getloadavg()[0]:.1f} at the end)")
    if bp:
        lines = []
        w = lines.append
        w("<!-- Written by tools/bench/pack_benchmark.py; do not edit by hand. -->")
        w(stamp + f", {a.repeats} repeats, medians.")
        w("")
        write_cube(w, gg, bp, bl)
        with open(os.path.join(a.out, "packer-cube.md"), "w") as f:
            f.write("\n".join(lines) + "\n")
        splice(a.doc, "cube", lines)
        print("\n".join(lines))
    if large:
        lines = []
        w = lines.append
        w("<!-- Written by tools/bench/pack_benchmark.py --large; do not edit by hand. -->")
        w(stamp + ".")
        w("")
        write_large(w, large, os.path.join(a.out, "packer-large.md"))
        with open(os.path.join(a.out, "packer-large.md"), "w") as f:
            f.write("\n".join(lines) + "\n")
        splice(a.doc, "large", lines)
        print("\n".join(lines))


def splice(doc, name, lines):
    """Replaces the text between <!-- bench:NAME --> and <!-- /bench:NAME --> in doc (if both are there)."""
    if not doc or not os.path.exists(doc):
        return
    text = open(doc).read()
    begin, end = f"<!-- bench:{name} -->", f"<!-- /bench:{name} -->"
    i, j = text.find(begin), text.find(end)
    if i < 0 or j < i:
        return
    with open(doc, "w") as f:
        f.write(text[:i + len(begin)] + "\n" + "\n".join(lines[1:]) + "\n" + text[j:])


def write_cube(w, gg, bp, bl):
    w("15 mm cube, radii 0.2-1.0 mm, overlap tolerance 1e-6, bonds within 1e-5 (the seed paper's base cube):")
    w("")
    w("| packer | spheres | solid fraction | fitted exponent | bonds | mean coordination | time [s] | peak RSS [MiB] |")
    w("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    if gg:
        w(f"| GenGeo (python3-gengeo, InsertGenerator3D) | {med(gg, 'particles'):.0f} | "
          f"{med(gg, 'solid_fraction'):.4f} | {med(gg, 'exponent'):.2f} | {med(gg, 'bonds'):.0f} | "
          f"{2 * med(gg, 'bonds') / med(gg, 'particles'):.2f} | {med(gg, 'seconds'):.2f} | {med(gg, 'rss_mib'):.0f} |")
    for name, rows in (("basalt-pack, dense (default)", bp),
                       ("basalt-pack, GenGeo-like: `--exponent 2.2 --target-fraction 0.62 --fill`", bl)):
        w(f"| {name} | {med(rows, 'particles'):.0f} | {med(rows, 'solid_fraction'):.4f} | "
          f"{med(rows, 'exponent'):.2f} | {med(rows, 'bonds'):.0f} | {med(rows, 'coordination'):.2f} | "
          f"{med(rows, 'seconds'):.3f} | {med(rows, 'rss_mib'):.0f} |")
    w("")
    if gg:
        w(f"Speed-up over GenGeo (median time / median time, same run): dense **{med(gg, 'seconds') / med(bp, 'seconds'):.0f}x**, "
          f"GenGeo-like **{med(gg, 'seconds') / med(bl, 'seconds'):.0f}x**. Times are the packers' own "
          "(packing + bonding, without start-up and file writing); basalt-pack's includes its statistics.")
        w("")


def write_large(w, large, previous):
    """One row per case; rows of cases not run this time are kept from the previous file."""
    rows = {}
    if os.path.exists(previous):
        for line in open(previous):
            if line.startswith("| ") and not line.startswith("| pack ") and not line.startswith("| ---"):
                rows[line.split(" | ")[0][2:]] = line.rstrip("\n")
    stamp = f"{datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC, load {os.getloadavg()[0]:.1f}"
    for r in large:
        rows[r["label"]] = (
            f"| {r['label']} | {r['particles']} | {r['solid_fraction']:.4f} | {r['seconds']:.1f} | {r['wall']:.1f} | "
            f"{r['user']:.1f} | {r['rss_mib']:.0f} | {r['rss_mib'] * 2 ** 20 / r['particles']:.0f} | {stamp} |")
    w("Large packs (one run each, `/usr/bin/time -v`; \"time\" is basalt-pack's own, packing + bonding + statistics;")
    w("wall adds start-up and writing the .geo file; on a machine shared with other work wall time is longer than")
    w("the CPU time by the load factor):")
    w("")
    w("| pack | spheres | solid fraction | time [s] | wall [s] | user CPU [s] | peak RSS [MiB] | bytes per sphere | measured |")
    w("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
    for line in rows.values():
        w(line)
    w("")


if __name__ == "__main__":
    main()
