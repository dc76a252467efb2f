#!/usr/bin/python3
"""Cost of in-situ pictures to the compute ranks: the same run with and without --render-every,
interleaved, 1 compute rank + 1 I/O rank (docs/io-ranks.md, "In-situ pictures"). Prints per run the loop's
wall and CPU time (compute rank), the compute ranks' wait for output, the I/O rank's CPU time and the
drawing time per picture, then medians and the ratio of the loop times.

  /usr/bin/python3 tools/bench/wave_tile_geo.py $BASALT_REFERENCE_DIR/cube1.geo 2 cube30.geo
  /usr/bin/python3 tools/bench/insitu_bench.py --geometry cube30.geo --steps 500 --render-every 100 --repeats 4
"""
import argparse
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


def run(a, render, out):
    env = bt.mpi_env(bt.RUN_AS_ROOT + bt.NO_GL)
    env.pop("DISPLAY", None)
    shutil.rmtree(out, ignore_errors=True)
    cmd = ["mpirun", "-np", "2", a.basalt_run, a.scene, "--geometry", a.geometry, "--steps", str(a.steps), "--quiet",
           "--io-ranks", "1", "--fields-every", "0", "--checkpoint-every", "0", "--frames-every", "0",
           "--output", str(out)]
    if render:
        cmd += ["--render-every", str(a.render_every), "--render", a.render]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stdout}\n{p.stderr}")
    x = bt.parse_run(p.stdout)
    r = {"loop": x["loop_s"], "cpu": x["cpu_s"], "wait": x["compute_wait_s"], "io_cpu": x["io_cpu_s"]}
    if "per_picture_s" in x:
        r.update(per_picture=x["per_picture_s"], longest=x["longest_s"], drawn=x["drawn"], due=x["due"])
    return r


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--basalt-run", default=str(ROOT / "build" / "bin" / "basalt-run"))
    ap.add_argument("--scene", default=str(ROOT / "scenes" / "wave.toml"))
    ap.add_argument("--geometry", required=True)
    ap.add_argument("--steps", type=int, default=500)
    ap.add_argument("--render-every", type=int, default=100)
    ap.add_argument("--render", default="color=velocity_z,cut=y,view=-y")
    ap.add_argument("--repeats", type=int, default=4)
    a = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="insitu-bench-"))
    rows = {False: [], True: []}
    for k in range(a.repeats):
        for render in (False, True) if k % 2 == 0 else (True, False):
            r = run(a, render, tmp / ("on" if render else "off"))
            rows[render].append(r)
            print(f"repeat {k + 1} {'with' if render else 'without'} pictures: " +
                  ", ".join(f"{key} {v}" for key, v in r.items()), flush=True)
    shutil.rmtree(tmp, ignore_errors=True)
    med = {render: {key: statistics.median(r[key] for r in rows[render]) for key in rows[render][0]}
           for render in rows}
    print(f"\n{a.steps} steps, 1 compute + 1 I/O rank, pictures every {a.render_every} ({a.render}), "
          f"{a.repeats} interleaved repeats, medians:")
    print("| run | loop wall [s] | loop CPU, compute rank [s] | compute waited [s] | I/O rank CPU [s] | per picture [s] | drawn |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for render in (False, True):
        m = med[render]
        pics = f"{m['per_picture']:.2f} (longest {m['longest']:.2f}) | {m['drawn']:.0f} of {m['due']:.0f}" if render else "| "
        print(f"| {'with' if render else 'without'} pictures | {m['loop']:.2f} | {m['cpu']:.2f} | {m['wait']:.3f} | "
              f"{m['io_cpu']:.2f} | {pics} |")
    print(f"loop wall time with / without: {med[True]['loop'] / med[False]['loop']:.3f}; "
          f"loop CPU time with / without: {med[True]['cpu'] / med[False]['cpu']:.3f}")


if __name__ == "__main__":
    main()
