#!/usr/bin/python3
"""A compute rank's cost of handing a checkpoint frame to the output (pack + submit), measured by
basalt-run itself (BASALT_FRAME_TIMES=1 prints each rank's median per run), for one or two
basalt-run binaries run interleaved on the same machine state. Prints the median over repeats of
compute rank 0's per-run median, and the ratio new / baseline.

  tools/bench/make_inputs.sh      # bench-inputs/cube30.geo and cube60.h5 (once)
  tools/bench/frame_times.py --basalt-run build/bin/basalt-run --baseline-run OTHER/bin/basalt-run \
      --geometry bench-inputs/cube30.geo --steps 600 --checkpoint-every 100 --repeats 5 [--io-ranks 1]
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

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

ROOT = Path(bt.ROOT)
LINE = re.compile(r"frame times \(rank 0\): (\d+) frames, median ([0-9.]+) ms")


def run(binary, a, out):
    env = bt.mpi_env(bt.RUN_AS_ROOT + bt.NO_GL, BASALT_FRAME_TIMES="1")
    shutil.rmtree(out, ignore_errors=True)
    cmd = bt.mpirun(a.compute_ranks + a.io_ranks) + [binary, a.scene, "--geometry", a.geometry,
           "--steps", str(a.steps), "--quiet", "--frames-every", "0", "--fields-every", "0",
           "--checkpoint-every", str(a.checkpoint_every), "--io-ranks", str(a.io_ranks), "--output", str(out)]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    m = LINE.search(p.stdout)
    if p.returncode != 0 or not m:
        sys.exit(f"failed or no frame times (BASALT_FRAME_TIMES support?): {' '.join(cmd)}\n{p.stdout}\n{p.stderr}")
    return float(m.group(2)), bt.parse_run(p.stdout)["loop_s"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--basalt-run", default=str(ROOT / "build/bin/basalt-run"))
    ap.add_argument("--baseline-run", default=None)
    ap.add_argument("--geometry", required=True)
    ap.add_argument("--scene", default=str(ROOT / "scenes/wave.toml"))
    ap.add_argument("--steps", type=int, default=600)
    ap.add_argument("--checkpoint-every", type=int, default=100)
    ap.add_argument("--compute-ranks", type=int, default=1)
    ap.add_argument("--io-ranks", type=int, default=1)
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    binaries = {"new": a.basalt_run}
    if a.baseline_run:
        binaries = {"baseline": a.baseline_run, **binaries}
    tmp = Path(tempfile.mkdtemp(prefix="basalt-frame-times-"))
    res = {k: [] for k in binaries}
    for _ in range(a.repeats):  # interleaved: load changes hit both alike
        for k, b in binaries.items():
            res[k].append(run(b, a, tmp / "out"))
    shutil.rmtree(tmp, ignore_errors=True)
    print(f"{a.geometry}: {a.compute_ranks} compute + {a.io_ranks} I/O rank(s), {a.steps} steps, checkpoint every "
          f"{a.checkpoint_every}; median of {a.repeats} runs (interleaved) of rank 0's median per run\n")
    print("| build | pack + submit per checkpoint, ms | loop s | per-run medians, ms |")
    print("| --- | --- | --- | --- |")
    med = {}
    for k, v in res.items():
        med[k] = statistics.median(x[0] for x in v)
        loop = statistics.median(x[1] for x in v)
        print(f"| {k} | {med[k]:.3f} | {loop:.3f} | {' '.join(f'{x[0]:.2f}' for x in v)} |")
    if "baseline" in med:
        print(f"\nnew / baseline: {med['new'] / med['baseline']:.3f} ({med['baseline'] / med['new']:.2f}x faster)")


if __name__ == "__main__":
    main()
