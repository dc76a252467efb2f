#!/usr/bin/python3
"""Cost of output in basalt-run: the paper's four output stages (none; field saver every step;
checkpoint every 100 steps; both) with --io-ranks 0 (1 rank computes and writes) and --io-ranks 1
(1 compute + 1 I/O rank), and the slow-storage experiment (--throttle-io-mbps). Prints Markdown
tables of medians over repeats and ratios against "none" with the same Q measured in the same run.

  tools/bench/output_bench.py --basalt-run build/bin/basalt-run --geometry /work/data/cube30.geo \
      --steps 300 --repeats 3 [--throttle 0,50,20,10,5]
The time is the stepping loop's ("done: N steps in X s"), start-up excluded.
"""
import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
STAGES = {
    "none": ["--fields-every", "0", "--checkpoint-every", "0"],
    "fields every step": ["--fields-every", "1", "--checkpoint-every", "0"],
    "checkpoint every 100": ["--fields-every", "0", "--checkpoint-every", "100"],
    "both": ["--fields-every", "1", "--checkpoint-every", "100"],
}


def run(a, q, extra, out):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1", OMPI_MCA_mpi_yield_when_idle="1")
    shutil.rmtree(out, ignore_errors=True)
    cmd = ["mpirun", "-np", str(1 + q), a.basalt_run, str(ROOT / "scenes/wave.toml"), "--geometry", a.geometry,
           "--steps", str(a.steps), "--quiet", "--frames-every", "0", "--io-ranks", str(q), "--output", str(out)] + extra
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stdout}\n{p.stderr}")
    loop = float(re.search(r"done: \d+ steps in ([0-9.]+) s", p.stdout).group(1))
    wait = float(re.search(r"compute ranks waited ([0-9.]+) s", p.stdout).group(1))
    return loop, wait


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--basalt-run", default=str(ROOT / "build/bin/basalt-run"))
    ap.add_argument("--geometry", required=True)
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--throttle", default="", help="MB/s values for the slow-storage table (0 = unthrottled)")
    ap.add_argument("--throttle-checkpoint-every", type=int, default=100)
    a = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="basalt-output-bench-"))
    print(f"geometry {a.geometry}, {a.steps} steps, median of {a.repeats} (interleaved), loop seconds\n")
    if not a.throttle:
        times = {(s, q): [] for s in STAGES for q in (0, 1)}
        waits = {(s, q): [] for s in STAGES for q in (0, 1)}
        for _ in range(a.repeats):  # interleave so that load changes hit every case alike
            for s, extra in STAGES.items():
                for q in (0, 1):
                    t, w = run(a, q, extra, tmp / "out")
                    times[(s, q)].append(t)
                    waits[(s, q)].append(w)
        print("| stage | Q = 0: loop s | vs none | Q = 1: loop s | vs none | Q = 1 compute wait s |")
        print("| --- | --- | --- | --- | --- | --- |")
        base = {q: statistics.median(times[("none", q)]) for q in (0, 1)}
        for s in STAGES:
            m0, m1 = statistics.median(times[(s, 0)]), statistics.median(times[(s, 1)])
            print(f"| {s} | {m0:.3f} | {100 * (m0 / base[0] - 1):+.1f} % | {m1:.3f} | {100 * (m1 / base[1] - 1):+.1f} % "
                  f"| {statistics.median(waits[(s, 1)]):.4f} |")
    else:
        rates = [float(x) for x in a.throttle.split(",")]
        extra = ["--fields-every", "0", "--checkpoint-every", str(a.throttle_checkpoint_every)]
        times = {(r, q): [] for r in rates for q in (0, 1)}
        waits = {(r, q): [] for r in rates for q in (0, 1)}
        for _ in range(a.repeats):
            for r in rates:
                for q in (0, 1):
                    t, w = run(a, q, extra + ["--throttle-io-mbps", str(r)], tmp / "out")
                    times[(r, q)].append(t)
                    waits[(r, q)].append(w)
        print(f"checkpoint every {a.throttle_checkpoint_every} steps, storage throttled to R MB/s (0 = not throttled)\n")
        print("| R MB/s | Q = 0: loop s | vs unthrottled | Q = 1: loop s | vs unthrottled | Q = 1 compute wait s |")
        print("| --- | --- | --- | --- | --- | --- |")
        base = {q: statistics.median(times[(rates[0], q)]) for q in (0, 1)}
        for r in rates:
            m0, m1 = statistics.median(times[(r, 0)]), statistics.median(times[(r, 1)])
            print(f"| {r:g} | {m0:.3f} | {m0 / base[0]:.2f}x | {m1:.3f} | {m1 / base[1]:.2f}x | "
                  f"{statistics.median(waits[(r, 1)]):.4f} |")
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
