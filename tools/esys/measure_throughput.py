#!/usr/bin/python3
"""Times the peer codes on the wave benchmark: particle-steps/s of the stepping loop, median of repeats.

    /usr/bin/python3 tools/esys/measure_throughput.py --geometry G.geo --steps 2000 --repeats 3 \
        --ranks 1,2 --codes esys,lammps --output out/timing [--markdown docs/data/x.md]

Runs are interleaved (esys 1, esys 2, lammps 1, lammps 2, then again) so that other load on the
machine falls on every configuration alike; the 1-minute load average is recorded before each run.
No output stages (no field saver, no checkpoint). ESyS: W workers + 1 master (mpirun -np W+1);
LAMMPS: R ranks. Results: OUTPUT/throughput.json and a markdown table on stdout.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

ESYS = os.path.join(HERE, "wave_benchmark.py")
LAMMPS = os.path.join(HERE, "..", "lammps", "wave_benchmark.sh")


def dims_for(workers):
    # split x first: the domain is padded 50 % above the cube, so z cuts would unbalance the load
    return {1: "1,1,1", 2: "2,1,1", 4: "2,2,1", 8: "2,2,2"}.get(workers, f"{workers},1,1")


def run_one(code, ranks, args, rundir):
    if code == "esys":
        cmd = ["/usr/bin/python3", ESYS, "--geometry", args.geometry, "--steps", str(args.steps),
               "--workers-dims", dims_for(ranks), "--output", rundir]
    else:
        cmd = [LAMMPS, "--geometry", args.geometry, "--steps", str(args.steps), "--ranks", str(ranks),
               "--grid", dims_for(ranks), "--output", rundir, "--skin", str(args.skin)]
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if proc.returncode != 0:
        print(proc.stdout[-2000:], file=sys.stderr)
        raise SystemExit(f"error: {' '.join(cmd)} exited with {proc.returncode}")
    with open(os.path.join(rundir, "timing.json")) as f:
        return json.load(f)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--geometry", default=bt.reference_cube(),
                   help="default $BASALT_REFERENCE_DIR/cube1.geo (default tests/data of this checkout)")
    p.add_argument("--steps", type=int, default=2000)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--ranks", default="1,2", help="comma list: ESyS workers / LAMMPS ranks")
    p.add_argument("--codes", default="esys,lammps")
    p.add_argument("--skin", type=float, default=0.04, help="LAMMPS neighbour skin, mm")
    p.add_argument("--output", default="throughput_out")
    args = p.parse_args()
    ranks = [int(r) for r in args.ranks.split(",")]
    codes = args.codes.split(",")
    for c in codes:
        if c not in ("esys", "lammps"):
            p.error(f"--codes: unknown code '{c}' (esys, lammps)")
    os.makedirs(args.output, exist_ok=True)
    results = {f"{c}:{r}": [] for c in codes for r in ranks}
    for rep in range(args.repeats):
        for c in codes:
            for r in ranks:
                load = os.getloadavg()[0]
                t = run_one(c, r, args, os.path.join(args.output, f"{c}_{r}_{rep}"))
                t["load_before"] = load
                results[f"{c}:{r}"].append(t)
                print(f"repeat {rep + 1}: {c} {r} rank(s): {t['particle_steps_per_s'] / 1e6:.3f} M particle-steps/s "
                      f"(loop {t['loop_s']:.2f} s, load {load:.2f})", flush=True)
    with open(os.path.join(args.output, "throughput.json"), "w") as f:
        json.dump(results, f, indent=1)
    n = next(iter(results.values()))[0]["particles"]
    print(f"\n{os.path.basename(args.geometry)}: {n} particles, {args.steps} steps, {args.repeats} repeats, "
          f"no output stages")
    print("| code | ranks | median M particle-steps/s | min | max | loads (1-min avg before each run) |")
    print("| --- | --- | --- | --- | --- | --- |")
    for key, runs in results.items():
        c, r = key.split(":")
        rates = [x["particle_steps_per_s"] / 1e6 for x in runs]
        label = f"{r} worker{'s' if int(r) > 1 else ''} + master" if c == "esys" else f"{r} rank{'s' if int(r) > 1 else ''}"
        loads = ", ".join(f"{x['load_before']:.1f}" for x in runs)
        print(f"| {'ESyS-Particle 2.3.5' if c == 'esys' else 'LAMMPS 29Sep2021u2'} | {label} | "
              f"{statistics.median(rates):.3f} | {min(rates):.3f} | {max(rates):.3f} | {loads} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
