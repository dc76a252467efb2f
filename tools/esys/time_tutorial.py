#!/usr/bin/python3
"""Times ESyS-Particle's tutorial scripts on ESyS and on Basalt's front end, interleaved (docs/esys.md, "How fast").

    /usr/bin/python3 tools/esys/time_tutorial.py --source TUTORIAL_DIR --scripts slope_fail hopper_flow \
        --steps hopper_flow=10000 --repeats 2 --workdir /tmp/timing [--build build]

TUTORIAL_DIR holds the tutorial's scripts as plain Python (extracted from ESyS's Doc/Tutorial/examples/*.py.tex,
which are not part of Basalt) with the files they read (floorMesh.msh). Each run gets a fresh copy of that folder;
`--steps NAME=N` replaces NAME's setNumTimeSteps(...) by N in both codes' copies (the same edit). Runs go ESyS,
Basalt, script after script, then again (so that other load on the machine falls on both alike); the 1-minute
load average is recorded before each. ESyS: mpirun -np 2 esysparticle (its master and one worker, as the
scripts ask: numWorkerProcesses = 1); Basalt: python3 -m basalt.esys, one process. Wall time from start to exit
(a run that hangs after its last output, as ESyS 2.3.5 may at exit, is timed to its last file and then ended)."""

import argparse
import os
import re
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)


def prepare(source, script, steps, rundir):
    if os.path.isdir(rundir):
        shutil.rmtree(rundir)
    shutil.copytree(source, rundir)
    path = os.path.join(rundir, script + ".py")
    if steps is not None:
        with open(path) as f:
            text = f.read()
        text, n = re.subn(r"setNumTimeSteps\s*\(\s*\d+\s*\)", f"setNumTimeSteps ({steps})", text)
        if n != 1:
            sys.exit(f"{path}: expected one setNumTimeSteps(...) call to shorten, found {n}")
        with open(path, "w") as f:
            f.write(text)
    return path


def timed(cmd, cwd, env, timeout, hang):
    """(wall seconds, CPU seconds of the run's processes, note): to exit, or to the last file written when the
    run outlives it by `hang` s (then no CPU time)."""
    t0 = time.time()
    with open(os.path.join(cwd, "stdout.txt"), "w") as out:
        p = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=out, stderr=subprocess.STDOUT, start_new_session=True)
        while True:
            pid, status, usage = os.wait4(p.pid, os.WNOHANG)  # usage: the run and the processes it waited for
            if pid:
                p.returncode = os.waitstatus_to_exitcode(status)
                break
            time.sleep(0.05)
            now = time.time()
            last = max([t0] + [m for m in (os.path.getmtime(os.path.join(cwd, f)) for f in os.listdir(cwd)
                                           if f != "stdout.txt") if m >= t0])
            if now - t0 > timeout or (now - last > hang and now - t0 > hang):
                os.killpg(p.pid, 9)  # the run's own process group (start_new_session)
                p.wait()
                return last - t0, None, f"ended after its last file (exit code {p.returncode})"
    wall = time.time() - t0
    if p.returncode != 0:
        return None, None, f"exit {p.returncode} (see {cwd}/stdout.txt)"
    return wall, usage.ru_utime + usage.ru_stime, ""


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--source", required=True, help="the folder of the tutorial's scripts (plain Python)")
    ap.add_argument("--scripts", nargs="+", required=True)
    ap.add_argument("--steps", nargs="*", default=[], help="NAME=N: run NAME for N steps (both codes)")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--workdir", required=True)
    ap.add_argument("--build", default=os.path.join(bt.ROOT, "build"))
    ap.add_argument("--timeout", type=float, default=1800)
    ap.add_argument("--hang", type=float, default=60, help="seconds without a new file after which a run that "
                    "has not exited is taken as hung")
    ap.add_argument("--esys", default="esysparticle")
    args = ap.parse_args()
    steps = {}
    for item in args.steps:
        name, _, n = item.partition("=")
        if not n.isdigit():
            sys.exit(f"--steps {item!r}: give NAME=N")
        steps[name] = int(n)
    env_b = dict(os.environ, PYTHONPATH=os.path.abspath(os.path.join(args.build, "python")))
    codes = {"esys": (bt.mpirun(2) + [args.esys], bt.esys_env()),
             "basalt": ([sys.executable, "-m", "basalt.esys"], env_b)}
    results = {}
    for rep in range(args.repeats):
        for script in args.scripts:
            for code, (cmd, env) in codes.items():
                rundir = os.path.abspath(os.path.join(args.workdir, f"{script}-{code}-{rep}"))
                path = prepare(args.source, script, steps.get(script), rundir)
                load = os.getloadavg()[0]
                wall, cpu, note = timed(cmd + [path], rundir, env, args.timeout, args.hang)
                results[(script, code, rep)] = (wall, cpu, load, note)
                print(f"{script} {code} run {rep + 1}: {'failed' if wall is None else f'{wall:.1f} s'}, CPU "
                      f"{'-' if cpu is None else f'{cpu:.1f} s'} (load {load:.1f}) {note}", flush=True)
    print("\n| script | steps | ESyS-Particle wall s (mpirun -np 2) | Basalt wall s (1 process) | ratio | "
          "CPU s ESyS / Basalt | load averages |")
    print("| --- | ---: | --- | --- | --- | --- | --- |")
    for script in args.scripts:
        e = [results[(script, "esys", r)] for r in range(args.repeats)]
        b = [results[(script, "basalt", r)] for r in range(args.repeats)]
        ratio = [f"{x[0] / y[0]:.1f}x" if x[0] and y[0] else "-" for x, y in zip(e, b)]
        fmt = lambda rows: ", ".join("-" if r[0] is None else f"{r[0]:.1f}" for r in rows)  # noqa: E731
        cpu = ", ".join(f"{'-' if x[1] is None else f'{x[1]:.1f}'} / {'-' if y[1] is None else f'{y[1]:.1f}'}"
                        for x, y in zip(e, b))
        loads = ", ".join(f"{x[2]:.1f}/{y[2]:.1f}" for x, y in zip(e, b))
        print(f"| {script} | {steps.get(script, 'as written')} | {fmt(e)} | {fmt(b)} | {', '.join(ratio)} | "
              f"{cpu} | {loads} |")


if __name__ == "__main__":
    main()
