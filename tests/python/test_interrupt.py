"""Ctrl-C during a Python-driven run (docs/python.md, "Ctrl-C"): SIGINT stops sim.run() at a whole step within
a fraction of a second and raises KeyboardInterrupt; the simulation stays usable (its state queried, 10 more
steps run), and Python's own SIGINT handler is back after the run. A script's own handler is called instead of
raising. On two compute ranks a SIGINT to one rank stops both at the same step."""

import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import basalt_tools  # (on sys.path by conftest.py)

HERE = Path(__file__).resolve().parent

SCRIPT = """
import math, os, signal, sys, time
from pathlib import Path
sys.path.insert(0, HERE)
from test_simulation import wave_scene
import basalt


def say(line):  # one write a line: mpirun passes on each rank's writes as they come
    sys.stdout.write(line + "\\n")
    sys.stdout.flush()


sim = basalt.Simulation(wave_scene(Path(OUT), steps=0, checkpoint_every=0))
rank = sim.rank
BEFORE_RUN
say(f"ready {rank} {os.getpid()}")
try:
    made = sim.run(10**9)
    say(f"returned {rank} {made} {sim.step}")
except KeyboardInterrupt:
    step = sim.step
    ke = sim.kinetic_energy()
    say(f"interrupted {rank} {step} {ke!r}")
    assert step > 0 and math.isfinite(ke), (step, ke)
    assert sim.run(10) == 10 and sim.step == step + 10
    say(f"resumed {rank} {sim.step}")
AFTER_RUN
sim.close()
"""

# After the run Python's own handler is back: a SIGINT to the process raises KeyboardInterrupt at once.
HANDLER_BACK = """
try:
    os.kill(os.getpid(), signal.SIGINT)
    time.sleep(10)
    print("handler not restored", flush=True)
except KeyboardInterrupt:
    print("handler restored", flush=True)
"""


def start(tmp_path, cmd_prefix=(), before_run="", after_run=""):
    script = tmp_path / "run.py"
    text = SCRIPT.replace("HERE", repr(str(HERE))).replace("OUT", repr(str(tmp_path / "out")))
    script.write_text(text.replace("BEFORE_RUN", before_run).replace("AFTER_RUN", after_run))
    return subprocess.Popen([*cmd_prefix, sys.executable, str(script)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=basalt_tools.mpi_env())


def wait_ready(p, ranks=1):
    """The pids of the ranks, once each has started its run's set-up (their "ready" lines)."""
    pids = {}
    while len(pids) < ranks:
        line = p.stdout.readline()
        if not line:
            pytest.fail(f"the script ended before its run: {p.wait()}\n{p.stderr.read()}")
        for rank, pid in re.findall(r"ready (\d+) (\d+)", line):  # (mpirun may join two ranks' lines)
            pids[int(rank)] = int(pid)
    return pids


def finish(p, seconds):
    """Waits `seconds` at most for the script's end: (its stdout lines, stderr, seconds it took)."""
    t0 = time.monotonic()
    try:
        out, err = p.communicate(timeout=seconds)
    except subprocess.TimeoutExpired:
        p.kill()
        out, err = p.communicate()
        pytest.fail(f"the run did not stop within {seconds} s of SIGINT:\n{out}\n{err}")
    return out.splitlines(), err, time.monotonic() - t0


def test_ctrl_c_stops_run_with_keyboard_interrupt(tmp_path):
    p = start(tmp_path, after_run=HANDLER_BACK)
    wait_ready(p)
    time.sleep(1.0)  # well into the run (the start-up is a fraction of a second)
    p.send_signal(signal.SIGINT)
    out, err, seconds = finish(p, 30)
    assert p.returncode == 0, "\n".join(out) + err
    interrupted = [line for line in out if line.startswith("interrupted")]
    assert interrupted, "\n".join(out) + err
    assert seconds < 5, f"took {seconds:.1f} s from SIGINT to the script's end"
    step = int(interrupted[0].split()[2])
    assert f"resumed 0 {step + 10}" in out, out
    assert "handler restored" in out, out


def test_ctrl_c_calls_the_scripts_own_handler(tmp_path):
    """A script's SIGINT handler is called after the run stopped; not raising, run() returns the steps made."""
    handler = "signal.signal(signal.SIGINT, lambda s, f: print('handler called', flush=True))"
    p = start(tmp_path, before_run=handler)
    wait_ready(p)
    time.sleep(1.0)
    p.send_signal(signal.SIGINT)
    out, err, _ = finish(p, 30)
    assert p.returncode == 0, "\n".join(out) + err
    assert "handler called" in out, out
    returned = [line.split() for line in out if line.startswith("returned")]
    assert returned and 0 < int(returned[0][2]) == int(returned[0][3]), out


@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
def test_sigint_to_one_rank_stops_both_at_one_step(tmp_path):
    p = start(tmp_path, cmd_prefix=("mpirun", "-np", "2"))
    pids = wait_ready(p, ranks=2)
    time.sleep(1.5)
    os.kill(pids[1], signal.SIGINT)  # one rank only: the ranks agree on it
    out, err, _ = finish(p, 60)
    assert p.returncode == 0, "\n".join(out) + err
    text = "\n".join(out)
    steps = dict(re.findall(r"interrupted (\d+) (\d+)", text))
    assert set(steps) == {"0", "1"} and steps["0"] == steps["1"], text
    assert len(re.findall(r"resumed \d+ \d+", text)) == 2, text
