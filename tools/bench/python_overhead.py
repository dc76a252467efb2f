"""What driving a run from Python costs (issue 44, docs/BENCHMARKS.md "Python"): the wave benchmark on the GenGeo
cube (tests/data/cube1.geo, 8,948 particles) run by basalt-run and by basalt.Simulation, interleaved, at 1 and
2 ranks; then the cost of a callback every step that reads numpy views of positions and velocities, and of one
every 100 steps (the views read in a callback that says it reads no velocities, velocities=False, measure the
Python call alone: the other pays the pass that completes the velocities too). The loop time only (basalt-run's "done: ... in X s"; Python's time around sim.run, the slowest
rank's), medians of --repeats interleaved runs.

    /usr/bin/python3 tools/bench/python_overhead.py [--steps 2000] [--repeats 3] [--ranks 1 2] [--json out.json]
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402

CHILD = r"""
import sys, time, basalt
scene, cube, out, steps, every = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5])
sim = basalt.Simulation(scene, geometry=cube, output=out)
if every > 0:
    def look(s):
        x, vx = s.particles.x, s.particles.vx
        return None
    sim.callback(look, every=abs(every), velocities=every > 0)
t = time.perf_counter()
sim.run(steps)
dt = sim.max(time.perf_counter() - t)
if sim.rank == 0:
    print(f"loop {dt:.6f}")
sim.close()
"""


def basalt_run(ranks, steps, out, bin):
    cmd = bt.basalt_run_command(bt.binary("basalt-run", bin=bin), bt.repo_path("scenes", "wave.toml"),
                                "--geometry", bt.reference_cube(), "--steps", str(steps), "--output", out,
                                "--fields-every", "0", "--quiet", np=ranks)
    text = bt.run(cmd, env=bt.mpi_env(ranks=ranks)).stdout
    return float(re.search(r"done: \d+ steps in ([0-9.]+) s", text).group(1))


def python_run(ranks, steps, out, every, pythonpath):
    env = bt.mpi_env(ranks=ranks, PYTHONPATH=pythonpath)
    script = os.path.join(out + ".py")
    with open(script, "w") as f:
        f.write(CHILD)
    scene = os.path.join(out + ".toml")
    # the same scene with fields off, as basalt-run's --fields-every 0
    text = open(bt.repo_path("scenes", "wave.toml")).read()
    text = re.sub(r"\[\[output\.fields\]\][^\[]*", "", text)
    with open(scene, "w") as f:
        f.write(text)
    cmd = [sys.executable, script, scene, bt.reference_cube(), out, str(steps), str(every)]
    if ranks > 1:  # (one rank without mpirun, as basalt_run_command runs basalt-run)
        cmd = bt.mpirun(ranks) + cmd
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=os.path.dirname(script))
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{p.stdout}\n{p.stderr}")
    return float(re.search(r"loop ([0-9.]+)", p.stdout).group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--bin", help="the build's bin folder (default build/bin)")
    ap.add_argument("--pythonpath", default=bt.repo_path("build", "python"))
    ap.add_argument("--json")
    args = ap.parse_args()
    args.pythonpath = os.path.abspath(args.pythonpath)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for ranks in args.ranks:
            times = {"basalt-run": [], "python": [], "callback every step": [], "callback every step, no velocities": [],
                     "callback every 100": []}
            for r in range(args.repeats):
                base = os.path.join(tmp, f"np{ranks}-{r}")
                times["basalt-run"].append(basalt_run(ranks, args.steps, base + "-cli", args.bin))
                times["python"].append(python_run(ranks, args.steps, base + "-py", 0, args.pythonpath))
                times["callback every step"].append(python_run(ranks, args.steps, base + "-cb1", 1, args.pythonpath))
                times["callback every step, no velocities"].append(
                    python_run(ranks, args.steps, base + "-cb1p", -1, args.pythonpath))
                times["callback every 100"].append(python_run(ranks, args.steps, base + "-cb100", 100,
                                                              args.pythonpath))
            med = {k: statistics.median(v) for k, v in times.items()}
            row = {"ranks": ranks, "steps": args.steps, "median_s": med, "all_s": times,
                   "python_over_basalt_run": med["python"] / med["basalt-run"],
                   "callback_us_per_call": 1e6 * (med["callback every step"] - med["python"]) / args.steps,
                   "callback_no_velocities_us_per_call":
                       1e6 * (med["callback every step, no velocities"] - med["python"]) / args.steps,
                   "callback_every_100_over_python": med["callback every 100"] / med["python"]}
            rows.append(row)
            print(f"np {ranks}: basalt-run {med['basalt-run']:.3f} s, Python {med['python']:.3f} s "
                  f"({row['python_over_basalt_run']:.3f}x); callback every step +{row['callback_us_per_call']:.1f} us "
                  f"per call (+{row['callback_no_velocities_us_per_call']:.1f} us reading no velocities); every 100 steps {row['callback_every_100_over_python']:.3f}x "
                  f"({args.steps} steps, medians of {args.repeats}, interleaved)", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"host": bt.host_summary() if hasattr(bt, "host_summary") else os.uname().nodename,
                       "time": time.strftime("%Y-%m-%d %H:%M"), "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
