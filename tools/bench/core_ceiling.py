#!/usr/bin/env python3
"""What a 2-rank speed-up can reach on this host: the same scene run alone on one core, and as two
independent copies at once, one per core (no MPI, no communication, no synchronisation). Two copies
finishing in the time of one would make 2.00; shared caches, memory bandwidth and the neighbours of
a shared virtual machine make it less. Each repeat also runs the scene at 1 and 2 MPI ranks, so the
measured speed-up and this ceiling come from the same minutes (docs/BENCHMARKS.md, "Two cores").

  source scripts/mpi-env.sh
  /usr/bin/python3 tools/bench/core_ceiling.py --scene scenes/ucs-esys.toml --steps 22000 --repeats 5

Prints one line per repeat and the medians; --json FILE keeps them.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)


def start(cmd):
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def loop_time(proc, what):
    out, _ = proc.communicate()
    r = bt.parse_run(out)
    if proc.returncode != 0 or "loop_s" not in r:
        sys.exit(f"core_ceiling.py: {what} failed (exit {proc.returncode}):\n{out[-2000:]}")
    return r["loop_s"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", required=True)
    ap.add_argument("--steps", type=int, required=True)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--bin", default=bt.bin_dir())
    ap.add_argument("--json")
    a = ap.parse_args()
    exe = os.path.realpath(os.path.join(a.bin, "basalt-run"))
    scene = os.path.realpath(a.scene)
    if not os.access(exe, os.X_OK):
        sys.exit(f"core_ceiling.py: no executable {exe}")
    if not os.path.isfile(scene):
        sys.exit(f"core_ceiling.py: no scene file {scene}")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        def run(core, tag):
            cmd = ["taskset", "-c", str(core), exe, scene, "--steps", str(a.steps), "--quiet",
                   "--output", os.path.join(tmp, tag)]
            return start(cmd)

        def mpi(ranks):
            cmd = bt.mpirun(ranks) + [exe, scene, "--steps", str(a.steps), "--quiet",
                   "--output", os.path.join(tmp, f"np{ranks}")]
            return loop_time(start(cmd), f"{ranks}-rank run")

        os.chdir(os.path.dirname(scene))
        for r in range(a.repeats):
            alone = [loop_time(run(c, f"alone{c}"), f"alone on core {c}") for c in (0, 1)]
            pair = [run(0, "pair0"), run(1, "pair1")]
            both = [loop_time(p, "one of the pair") for p in pair]
            np1, np2 = mpi(1), mpi(2)
            row = {"alone_s": statistics.mean(alone), "pair_s": max(both), "np1_s": np1, "np2_s": np2}
            row["ceiling"] = 2 * row["alone_s"] / row["pair_s"]
            row["speedup"] = np1 / np2
            rows.append(row)
            print(f"repeat {r + 1}: alone {alone[0]:.3f}/{alone[1]:.3f} s, pair {both[0]:.3f}/{both[1]:.3f} s "
                  f"-> ceiling {row['ceiling']:.2f}x; MPI 1 rank {np1:.3f} s, 2 ranks {np2:.3f} s "
                  f"-> speed-up {row['speedup']:.2f}x", flush=True)
    med = {k: statistics.median(r[k] for r in rows) for k in rows[0]}
    print(f"median: ceiling {med['ceiling']:.2f}x (two independent copies), 2-rank speed-up {med['speedup']:.2f}x, "
          f"{med['speedup'] / med['ceiling']:.0%} of the ceiling")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"scene": a.scene, "steps": a.steps, "repeats": rows, "median": med}, f, indent=1)


if __name__ == "__main__":
    main()
