#!/usr/bin/env python3
"""Soak test of checkpoints and restarts (issue 16): a run killed with SIGKILL at random moments and
restarted from its newest complete checkpoint, again and again, must end bit for bit where the same run
ends uninterrupted: the final checkpoint byte for byte and fields.csv equal.

    /usr/bin/python3 tools/soak/soak.py --build build --geometry $BASALT_REFERENCE_DIR/cube1.geo \
        [--steps 3000] [--every 100] [--np 2] [--io-ranks 1] [--kills 10] [--seed 1] [--work DIR]

Each round starts basalt-run (fresh, or --restart OUT/ with the steps still to go), lets it run for a
random time between 0.2 s and half the uninterrupted run's wall time, and kills mpirun and every rank with
SIGKILL (no chance to flush; the ranks are found by mpirun's session, since Open MPI gives each rank its
own process group). The newest checkpoint whose HDF5 opens is the restart point (basalt-run
picks the same one; a checkpoint cut off mid-write is passed over). After --kills kills the run is left to
finish. Exit status 0 when the final files are equal, 1 otherwise; a summary line per round on stdout.
"""
import argparse
import filecmp
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)


def mpirun(np_total):
    return bt.mpirun(np_total) if np_total > 1 else []


def newest_complete(out: Path):
    """Step of the newest checkpoint that HDF5 opens, or None."""
    found = sorted(((int(m.group(1)), f) for f in out.glob("ckpt_*.h5")
                    if (m := re.fullmatch(r"ckpt_(\d+)\.h5", f.name))), reverse=True)
    for s, f in found:
        r = subprocess.run(["/usr/bin/python3", "-c", f"import h5py; h5py.File({str(f)!r}, 'r').close()"],
                           capture_output=True)
        if r.returncode == 0:
            return s
    return None


def session_pids(sid):
    pids = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                if os.getsid(int(d.name)) == sid:
                    pids.append(int(d.name))
            except (ProcessLookupError, PermissionError):
                pass
    return pids


def kill_session(proc):
    """SIGKILL mpirun and every rank: Open MPI gives each rank a process group of its own (killing
    mpirun's group leaves them running, still writing), but they stay in mpirun's session."""
    for _ in range(50):
        pids = session_pids(proc.pid)
        if not pids:
            break
        for pid in pids:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        time.sleep(0.05)
    proc.wait()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--scene", default=str(Path(__file__).resolve().parents[2] / "scenes" / "wave.toml"))
    ap.add_argument("--geometry", required=True)
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--every", type=int, default=100, help="checkpoint every N steps")
    ap.add_argument("--np", type=int, default=2, help="compute ranks")
    ap.add_argument("--io-ranks", type=int, default=1)
    ap.add_argument("--kills", type=int, default=10)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--work", default="soak-work")
    a = ap.parse_args()
    exe = bt.binary("basalt-run", build=a.build)
    work = Path(a.work)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    ref, out = work / "reference", work / "soak"
    base = [*mpirun(a.np + a.io_ranks), exe, a.scene, "--geometry", a.geometry, "--io-ranks", str(a.io_ranks),
            "--checkpoint-every", str(a.every), "--quiet"]

    t0 = time.monotonic()
    r = subprocess.run(base + ["--steps", str(a.steps), "--output", str(ref)], capture_output=True, text=True)
    wall = time.monotonic() - t0
    if r.returncode != 0:
        sys.exit(f"soak: the uninterrupted run failed:\n{r.stderr}")
    print(f"uninterrupted: {a.steps} steps in {wall:.1f} s")

    rng = random.Random(a.seed)
    kills = restarts = rounds = 0
    while True:
        rounds += 1
        step = newest_complete(out) if out.exists() else None
        if step is None:
            cmd = base + ["--steps", str(a.steps), "--output", str(out)]
        else:
            if step >= a.steps:
                break
            cmd = base + ["--restart", str(out) + "/", "--steps", str(a.steps - step), "--output", str(out)]
            restarts += 1
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                start_new_session=True)
        if kills < a.kills:
            delay = rng.uniform(0.2, max(0.3, 0.5 * wall))
            try:
                proc.wait(timeout=delay)
            except subprocess.TimeoutExpired:
                kill_session(proc)
                kills += 1
                print(f"round {rounds}: from step {step or 0}, killed after {delay:.2f} s "
                      f"(newest complete checkpoint now {newest_complete(out)})")
                continue
        err = proc.communicate()[1]
        if proc.returncode != 0:
            sys.exit(f"soak: basalt-run failed (exit {proc.returncode}) from step {step}:\n{err}")
        print(f"round {rounds}: from step {step or 0}, finished")

    final = f"ckpt_{a.steps:06d}.h5"
    same_ckpt = filecmp.cmp(ref / final, out / final, shallow=False)
    same_fields = filecmp.cmp(ref / "fields.csv", out / "fields.csv", shallow=False)
    print(f"{kills} kills, {restarts} restarts: final checkpoint {'equal' if same_ckpt else 'DIFFERENT'} "
          f"byte for byte, fields.csv {'equal' if same_fields else 'DIFFERENT'}")
    sys.exit(0 if same_ckpt and same_fields else 1)


if __name__ == "__main__":
    main()
