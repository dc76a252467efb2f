#!/usr/bin/python3
"""Two builds of basalt-run on the wave benchmark, interleaved: the check that a change keeps the
benchmark's speed and memory (docs/BENCHMARKS.md, "Architecture change").

    /usr/bin/python3 tools/bench/build_ab.py --base OLD/build --new build --repeats 7 --out docs/bench/build_ab.md

Cases: the 15 mm GenGeo cube ($BASALT_REFERENCE_DIR/cube1.geo, 8,948 particles) and the 30 mm cube made
by tiling it 2x2x2 (tools/bench/wave_tile_geo.py, 71,584 particles), each at 1 and 2 ranks, with
scenes/wave.toml. Every repeat runs the base build then the new one (the order alternates between
repeats) on the same case, so both see the same machine load; the report gives each build's median
throughput (particles x steps / loop seconds, as basalt-run prints it) and the median of the
per-repeat ratios new / base. Memory: the solver's array bytes per particle that basalt-run prints, and
the peak RSS (/usr/bin/time -v) on cube1.geo tiled 5x5x5 (1,118,500 particles) at 1 rank, minus the
peak RSS on cube1.geo, per extra particle (removes the fixed start-up cost).
Instructions (--callgrind, 1 rank): valgrind's callgrind counts the instructions of two runs of
different lengths; their difference over the step difference is the instructions per step of the
loop alone, the same on a loaded machine as on an idle one.
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

ROOT = bt.ROOT


def run(build, geo, np_, steps, out, timed=False):
    cmd = bt.basalt_run_command(bt.binary("basalt-run", build=build), os.path.join(ROOT, "scenes", "wave.toml"),
                                "--geometry", geo, "--steps", steps, "--output", out, "--quiet", "--fields-every", "0",
                                np=np_, timed=timed)
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stdout}\n{p.stderr}")
    r = bt.parse_run(p.stdout)
    return r["particle_steps_per_s"], float(r["bytes_per_particle"]), bt.parse_time_v(p.stderr).get("max_rss_kb", 0)


def instructions_per_step(build, geo, s1, s2, out):
    counts = []
    for steps in (s1, s2):
        cmd = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
               bt.binary("basalt-run", build=build), os.path.join(ROOT, "scenes", "wave.toml"), "--geometry", geo,
               "--steps", str(steps), "--output", out, "--quiet", "--fields-every", "0"]
        p = subprocess.run(cmd, capture_output=True, text=True)
        m = re.search(r"Collected : ([0-9]+)", p.stderr)
        if p.returncode != 0 or not m:
            sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr[-2000:]}")
        counts.append(int(m.group(1)))
    return (counts[1] - counts[0]) / (s2 - s1)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--base", required=True, help="build folder of the baseline (holds bin/basalt-run)")
    ap.add_argument("--new", required=True, help="build folder of the change")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--steps15", type=int, default=5000)
    ap.add_argument("--steps30", type=int, default=1000)
    ap.add_argument("--no-memory", action="store_true")
    ap.add_argument("--no-speed", action="store_true", help="skip the timed runs")
    ap.add_argument("--callgrind", action="store_true", help="instructions per step at 1 rank (valgrind)")
    ap.add_argument("--out", default="", help="markdown report")
    a = ap.parse_args()
    cube15 = bt.reference_cube()
    tmp = tempfile.mkdtemp(prefix="build_ab_")
    tile = os.path.join(ROOT, "tools", "bench", "wave_tile_geo.py")
    cube30 = os.path.join(tmp, "cube30-tiled.geo")
    subprocess.run(["/usr/bin/python3", tile, cube15, "2", cube30], check=True, capture_output=True)
    builds = {"base": a.base, "new": a.new}
    cases = [("15 mm (8,948)", cube15, 1, a.steps15), ("15 mm (8,948)", cube15, 2, a.steps15),
             ("30 mm (71,584)", cube30, 1, a.steps30), ("30 mm (71,584)", cube30, 2, a.steps30)]
    rows, arrays = [], {}
    for name, geo, np_, steps in ([] if a.no_speed else cases):
        rates = {"base": [], "new": []}
        ratios = []
        for r in range(a.repeats):
            order = ["base", "new"] if r % 2 == 0 else ["new", "base"]
            got = {}
            for b in order:
                rate, arr, _ = run(builds[b], geo, np_, steps, os.path.join(tmp, b))
                got[b] = rate
                rates[b].append(rate)
                arrays[(b, name)] = arr
            ratios.append(got["new"] / got["base"])
        row = (name, np_, statistics.median(rates["base"]), statistics.median(rates["new"]),
               statistics.median(ratios), min(ratios), max(ratios))
        rows.append(row)
        print(f"{name} np {np_}: base {row[2] / 1e6:.2f} M, new {row[3] / 1e6:.2f} M particle-steps/s, "
              f"new/base median {row[4]:.3f} (range {row[5]:.3f}-{row[6]:.3f})", flush=True)
    insn = []
    if a.callgrind:
        for name, geo, np_, steps in cases:
            if np_ != 1:
                continue
            s1, s2 = (100, 400) if geo == cube15 else (20, 80)
            per = {b: instructions_per_step(builds[b], geo, s1, s2, os.path.join(tmp, b)) for b in builds}
            insn.append((name, per["base"], per["new"]))
            print(f"{name} np 1: instructions per step base {per['base'] / 1e6:.2f} M, new {per['new'] / 1e6:.2f} M, "
                  f"new/base {per['new'] / per['base']:.4f}", flush=True)
    mem = {}
    if not a.no_memory:
        big = os.path.join(tmp, "cube-tiled5.geo")
        subprocess.run(["/usr/bin/python3", tile, cube15, "5", big], check=True, capture_output=True)
        for b in builds:
            _, arr_big, rss_big = run(builds[b], big, 1, 20, os.path.join(tmp, b), timed=True)
            _, _, rss_small = run(builds[b], cube15, 1, 20, os.path.join(tmp, b), timed=True)
            mem[b] = (arr_big, (rss_big - rss_small) * 1024 / (1118500 - 8948))
            print(f"memory {b}: solver arrays {arr_big:.0f} B/particle, peak RSS {mem[b][1]:.0f} B/particle "
                  f"(1,118,500 particles)", flush=True)
    if a.out:
        lines = ["# Wave benchmark: two builds interleaved", "",
                 f"`/usr/bin/python3 tools/bench/build_ab.py --base {a.base} --new {a.new} --repeats {a.repeats}`", "",
                 f"{a.repeats} repeats per case, the two builds alternating; {a.steps15} steps on the 15 mm cube, "
                 f"{a.steps30} on the 30 mm cube (cube1.geo tiled 2x2x2), scenes/wave.toml, no field saver.", "",
                 "| case | ranks | base (M particle-steps/s) | new | new / base (median) | range |",
                 "| --- | ---: | ---: | ---: | ---: | --- |"]
        for name, np_, b, n, med, lo, hi in rows:
            lines.append(f"| {name} | {np_} | {b / 1e6:.2f} | {n / 1e6:.2f} | {med:.3f} | {lo:.3f} - {hi:.3f} |")
        if insn:
            lines += ["", "| instructions per step (callgrind, 1 rank, loop only) | base | new | new / base |",
                      "| --- | ---: | ---: | ---: |"]
            for name, b, n in insn:
                lines.append(f"| {name} | {b / 1e6:.3f} M | {n / 1e6:.3f} M | {n / b:.4f} |")
        if mem:
            lines += ["", "| memory (cube1.geo tiled 5x5x5, 1,118,500 particles, 1 rank) | base | new |",
                      "| --- | ---: | ---: |",
                      f"| solver arrays, bytes per particle | {mem['base'][0]:.0f} | {mem['new'][0]:.0f} |",
                      f"| peak RSS per extra particle (vs cube1.geo) | {mem['base'][1]:.0f} | {mem['new'][1]:.0f} |"]
        with open(a.out, "w") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
