#!/usr/bin/python3
"""Cost of output in basalt-run: the paper's four output stages (none; field saver every step;
checkpoint every 100 steps; both) with --io-ranks 0 (1 rank computes and writes) and --io-ranks 1
(1 compute + 1 I/O rank), and the slow-storage experiment (--throttle-io-mbps). Prints Markdown
tables of medians over repeats and ratios against "none" with the same Q measured in the same run.

  tools/bench/make_inputs.sh      # bench-inputs/cube30.geo and cube60.h5 (once)
  tools/bench/output_bench.py --basalt-run build/bin/basalt-run --geometry bench-inputs/cube30.geo \
      --steps 300 --repeats 3 [--throttle 0,50,20,10,5] [--baseline-run OTHER/bin/basalt-run]
With --baseline-run, "none" and "checkpoint every 100" also run with that binary (e.g. the previous
commit built in another folder), interleaved with the others: a before/after comparison in one session.
With --esys, ESyS-Particle 2.3.5 (tools/esys/wave_benchmark.py: 1 worker + master, its own field saver and
checkpointer) runs the same four stages on the same .geo file, interleaved with Basalt's runs.
The time is the stepping loop's ("done: N steps in X s"), start-up excluded.
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

ROOT = Path(bt.ROOT)
STAGES = {
    "none": ["--fields-every", "0", "--checkpoint-every", "0"],
    "fields every step": ["--fields-every", "1", "--checkpoint-every", "0"],
    "checkpoint every 100": ["--fields-every", "0", "--checkpoint-every", "100"],
    "both": ["--fields-every", "1", "--checkpoint-every", "100"],
}
BASELINE = " (baseline build)"  # suffix of the stages run with --baseline-run's binary


def run(a, q, extra, out):
    env = bt.mpi_env(bt.RUN_AS_ROOT + bt.NO_GL, OMPI_MCA_mpi_yield_when_idle="0")
    # Compute ranks should not yield (the I/O rank sleeps by itself); hwloc's GL probe would connect to an
    # X server on :0 if another session runs one, and die when it goes away.
    shutil.rmtree(out, ignore_errors=True)
    binary = a.basalt_run
    if extra and extra[0] == "--baseline":
        binary, extra = a.baseline_run, extra[1:]
    cmd = bt.mpirun(1 + q) + [binary, a.scene, "--geometry", a.geometry, "--steps", str(a.steps), "--quiet",
                              "--frames-every", "0", "--io-ranks", str(q), "--output", str(out)] + extra
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stdout}\n{p.stderr}")
    r = bt.parse_run(p.stdout)
    return r["loop_s"], r["compute_wait_s"], r["cpu_s"]


def run_esys(a, stage, out):
    """ESyS-Particle's loop seconds for one of the four stages (its field saver: kinetic energy every step)."""
    extra = {"none": [], "fields every step": ["--fieldsaver"], "checkpoint every 100": ["--checkpoint-every", "100"],
             "both": ["--fieldsaver", "--checkpoint-every", "100"]}[stage]
    shutil.rmtree(out, ignore_errors=True)
    cmd = ["/usr/bin/python3", str(ROOT / "tools/esys/wave_benchmark.py"), "--geometry", a.geometry,
           "--steps", str(a.steps), "--output", str(out)] + extra
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stdout}\n{p.stderr}")
    with open(Path(out) / "timing.json") as f:
        return json.load(f)["loop_s"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--basalt-run", default=str(ROOT / "build/bin/basalt-run"))
    ap.add_argument("--baseline-run", default=None, help="a second basalt-run binary to compare with")
    ap.add_argument("--geometry", required=True)
    ap.add_argument("--scene", default=str(ROOT / "scenes/wave.toml"))
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--throttle", default="", help="MB/s values for the slow-storage table (0 = unthrottled)")
    ap.add_argument("--throttle-checkpoint-every", type=int, default=100)
    ap.add_argument("--stages", default="", help="';'-separated subset of the stages (default: all)")
    ap.add_argument("--esys", action="store_true", help="also run the four stages with ESyS-Particle (.geo only)")
    ap.add_argument("--output-root", default=None, help="where the runs write (default: the system's temp folder; "
                    "/dev/shm takes the disk out of the measurement)")
    a = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="basalt-output-bench-", dir=a.output_root))
    print(f"geometry {a.geometry}, {a.steps} steps, median of {a.repeats} (interleaved), loop seconds, "
          f"output under {tmp.parent}\n")
    if a.stages:
        for s in list(STAGES):
            if s not in a.stages.split(";") and s != "none":
                del STAGES[s]
    esys = {}

    def table(cases, label, extra_of, base_case):
        res = {(c, q): [] for c in cases for q in (0, 1)}
        for _ in range(a.repeats):  # interleave so that load changes hit every case alike
            for c in cases:
                for q in (0, 1):
                    res[(c, q)].append(run(a, q, extra_of(c), tmp / "out"))
                if a.esys and c in STAGES and not c.endswith(BASELINE):
                    esys.setdefault(c, []).append(run_esys(a, c, tmp / "esys"))
        med = {k: [statistics.median(x[i] for x in v) for i in range(3)] for k, v in res.items()}
        print(f"| {label} | Q = 0: loop s | vs {base_case} | CPU s | vs {base_case} | Q = 1: loop s | vs {base_case} "
              f"| CPU s | vs {base_case} | Q = 1 compute wait s |")
        print("| --- " * 10 + "|")
        for c in cases:
            row = f"| {c} "
            for q in (0, 1):
                t, w, cpu = med[(c, q)]
                bt, _, bcpu = med[(base_case, q)]
                row += f"| {t:.3f} | {100 * (t / bt - 1):+.1f} % | {cpu:.3f} | {100 * (cpu / bcpu - 1):+.1f} % "
            print(row + f"| {med[(c, 1)][1]:.4f} |")
        if esys:
            e0 = statistics.median(esys["none"])
            print(f"\nESyS-Particle 2.3.5 (1 worker + master), same geometry and steps, median of {a.repeats}, "
                  "against Basalt with one I/O rank from the same runs:\n")
            print("| stage | ESyS loop s | vs none | Basalt Q = 1 loop s | vs none | ESyS / Basalt |")
            print("| --- " * 6 + "|")
            for c in esys:
                e, t, bt = statistics.median(esys[c]), med[(c, 1)][0], med[(base_case, 1)][0]
                print(f"| {c} | {e:.2f} | {100 * (e / e0 - 1):+.1f} % | {t:.3f} | {100 * (t / bt - 1):+.1f} % "
                      f"| {e / t:.0f}x |")

    if a.baseline_run:
        for s in [s for s in ["none", "checkpoint every 100"] if s in STAGES]:
            STAGES[s + BASELINE] = ["--baseline"] + STAGES[s]
    if not a.throttle:
        table(list(STAGES), "stage", lambda c: STAGES[c], "none")
    else:
        rates = [float(x) for x in a.throttle.split(",")]
        every = str(a.throttle_checkpoint_every)
        print(f"checkpoint every {every} steps, storage throttled to R MB/s (0 = not throttled)\n")
        table(rates, "R MB/s", lambda r: ["--fields-every", "0", "--checkpoint-every", every,
                                          "--throttle-io-mbps", str(r)], rates[0])
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
