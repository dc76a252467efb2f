#!/usr/bin/python3
"""Runs tutorial-style ESyS-Particle scripts on ESyS-Particle and on Basalt's ESyS front end
(`python3 -m basalt.esys`, docs/esys.md) in the same run, and compares what they print and write.

    /usr/bin/python3 tools/esys/compare_tutorial.py [--scripts collide fall settle] [--workdir DIR]
        [--tolerance 1e-6] [--build build | --pythonpath DIR] [--esys esysparticle] [--doc docs/esys.md]
        [--args ARG...] [--spread-args ARG...] [--num-time-steps N] [--spread-replace OLD NEW]

The scripts are ours (tests/python/esys_scripts/), in the style of ESyS's tutorial. ESyS runs as
`mpirun -np 2 esysparticle SCRIPT` (1 master + 1 worker), Basalt as `python3 -m basalt.esys SCRIPT`, each in
its own folder DIR/{esys,basalt}/NAME. Compared, row by row: the numbers of the lines the scripts print
(runnables), every field saver's file and every text checkpoint (particle rows matched by id; the header
text exactly). A quantity (one column of one kind of file) passes when max |Basalt - ESyS| <= tolerance x its
range over ESyS's rows (its largest magnitude when the range is 0, 1 when both are 0). Prints a table (and
with --doc writes it into docs/esys.md between the compare_tutorial markers) and the wall times of both.
--args passes arguments to every script (block_large.py's block size); with --spread-args ESyS runs a second
time with those arguments (a perturbed run, e.g. block_large.py's nudge) and a quantity above the tolerance
still passes when Basalt is no further from ESyS than ESyS is from itself.
A script may be given as ESyS's source holds the tutorial's (Doc/Tutorial/examples/NAME.py.tex, LaTeX-wrapped):
its verbatim block is run, from a copy in DIR/scripts/ beside the copies of the other examples it imports
(rot_compress.py.tex and its WallLoader.py.tex). With --num-time-steps N every script runs from such a copy whose
setNumTimeSteps(...) argument is N (a shortened run; the script is otherwise unchanged), and with --spread-replace
the perturbed ESyS run takes a copy with the text OLD replaced by NEW (e.g. a wall's position nudged by 1e-9, for
a script that takes no arguments).
Exit 1 on a mismatch; exit 3 (after Basalt's runs, nothing compared) when ESyS-Particle is not installed.
"""

import argparse
import collections
import os
import re
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

SCRIPTS = os.path.join(bt.ROOT, "tests", "python", "esys_scripts")
BEGIN, END = "<!-- compare_tutorial:begin -->", "<!-- compare_tutorial:end -->"
NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


def run(cmd, cwd, env, timeout):
    os.makedirs(cwd, exist_ok=True)
    for f in os.listdir(cwd):
        os.remove(os.path.join(cwd, f))
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, time.perf_counter() - t0, f"timed out after {timeout} s"
    wall = time.perf_counter() - t0
    with open(os.path.join(cwd, "stdout.txt"), "w") as f:
        f.write(p.stdout)
    if p.returncode != 0:
        return None, wall, f"exit {p.returncode}: {p.stderr[-2000:]}"
    return p.stdout, wall, ""


def verbatim(path):
    """A tutorial example's Python: the verbatim block of ESyS's NAME.py.tex, or the file itself."""
    with open(path) as f:
        text = f.read()
    if not path.endswith(".tex"):
        return text
    m = re.search(r"\\begin\{verbatim\}\n(.*?)\\end\{verbatim\}", text, re.S)
    if not m:
        sys.exit(f"{path}: no verbatim block")
    return m.group(1)


def script_copy(script, folder, steps=None, replace=None):
    """The script (a .py or ESyS's .py.tex) written into folder as NAME.py with the modules it imports from its own
    folder (.py or .py.tex); its setNumTimeSteps(...) argument set to steps, and replace = (OLD, NEW) applied, when
    given. Returns the copy's path."""
    os.makedirs(folder, exist_ok=True)
    text = verbatim(script)
    if steps is not None:
        text, n = re.subn(r"(setNumTimeSteps\s*\(\s*)\d+(\s*\))", rf"\g<1>{steps}\g<2>", text)
        if n == 0:
            sys.exit(f"{script}: no setNumTimeSteps(N) to shorten")
    if replace is not None:
        if replace[0] not in text:
            sys.exit(f"{script}: --spread-replace text {replace[0]!r} not found")
        text = text.replace(replace[0], replace[1])
    home = os.path.dirname(os.path.abspath(script))
    for module in re.findall(r"^\s*(?:from|import)\s+(\w+)", text, re.M):
        for ext in (".py", ".py.tex"):
            if os.path.exists(os.path.join(home, module + ext)):
                with open(os.path.join(folder, module + ".py"), "w") as f:
                    f.write(verbatim(os.path.join(home, module + ext)))
                break
    name = re.sub(r"\.py(\.tex)?$", "", os.path.basename(script))
    path = os.path.join(folder, name + ".py")
    with open(path, "w") as f:
        f.write(text)
    return path


def printed_rows(stdout):
    """{key: [numbers...] rows} of the lines a script prints that start with a word and hold numbers."""
    rows = collections.defaultdict(list)
    for line in stdout.splitlines():
        words = line.split()
        if len(words) > 1 and re.fullmatch(r"[a-z_]+", words[0]) and all(NUMBER.match(w) for w in words[1:]):
            rows[words[0]].append([float(w) for w in words[1:]])
    return rows


def numbers(path):
    with open(path) as f:
        return [[float(w) for w in line.split()] for line in f if line.strip()]


def checkpoint_rows(path):
    """{id: row} of an ESyS text checkpoint's particle lines (PREFIX_t=T_1.txt)."""
    with open(path) as f:
        lines = f.read().splitlines()
    n = int(lines[0])
    return {int(float(line.split()[4])): [float(w) for w in line.split()] for line in lines[1:1 + n]}, lines[1 + n:]


CHECKPOINT_COLUMNS = [("position", 0, 3), ("radius, id, tag, mass", 3, 7), ("initial position", 7, 10),
                      ("position at the last neighbour rebuild", 10, 13), ("velocity", 13, 16),
                      ("force", 16, 19), ("circular shift", 19, 22)]
# RotSphere checkpoints (ESyS 2.3.5, measured): the orientation w x y z and the angular velocity follow
ROTATIONAL_COLUMNS = [("orientation", 22, 26), ("angular velocity", 26, 29)]


def quantities(name, esys_dir, basalt_dir, esys_out, basalt_out):
    """(quantity, rows, [esys values], [basalt values]) or (quantity, error text)."""
    out = []
    pe, pb = printed_rows(esys_out), printed_rows(basalt_out)
    for key in sorted(set(pe) | set(pb)):
        a, b = pe.get(key, []), pb.get(key, [])
        if len(a) != len(b) or any(len(x) != len(y) for x, y in zip(a, b)):
            out.append((f"printed `{key}` lines", f"{len(a)} lines (ESyS) against {len(b)} (Basalt)"))
            continue
        for c in range(len(a[0]) if a else 0):
            out.append((f"printed `{key}` column {c + 1}", len(a), [r[c] for r in a], [r[c] for r in b]))
    files = sorted(set(os.listdir(esys_dir)) | set(os.listdir(basalt_dir)))
    groups = collections.defaultdict(lambda: [[], [], 0])
    for f in files:
        if f == "stdout.txt" or f.endswith((".geo", ".msh")):  # the script's own input (geo_read, mesh_drop)
            continue
        fe, fb = os.path.join(esys_dir, f), os.path.join(basalt_dir, f)
        if not (os.path.exists(fe) and os.path.exists(fb)):
            out.append((f"file {f}", "written by " + ("ESyS only" if os.path.exists(fe) else "Basalt only")))
            continue
        if re.search(r"_t=\d+_0\.txt$", f):
            with open(fe) as x, open(fb) as y:
                same = x.read() == y.read()
            g = groups["checkpoint headers (text)"]
            g[0].append(0.0)
            g[1].append(0.0 if same else 1e300)
            g[2] += 1
            continue
        if re.search(r"_t=\d+_1\.txt$", f):
            (re_, tail_e), (rb, tail_b) = checkpoint_rows(fe), checkpoint_rows(fb)
            if sorted(re_) != sorted(rb) or tail_e != tail_b:
                out.append((f"checkpoint {f}", "different particles or sections"))
                continue
            width = min(len(r) for r in (*re_.values(), *rb.values())) if re_ else 0
            for label, lo, hi in CHECKPOINT_COLUMNS + (ROTATIONAL_COLUMNS if width >= 29 else []):
                g = groups[f"checkpoints: {label}"]
                for pid in sorted(re_):
                    g[0].extend(re_[pid][lo:hi])
                    g[1].extend(rb[pid][lo:hi])
                g[2] += len(re_)
            continue
        a, b = numbers(fe), numbers(fb)
        stem = re.sub(r"\.\d+\.dat$", ".N.dat", f)
        if len(a) != len(b) or any(len(x) != len(y) for x, y in zip(a, b)):
            out.append((f"file {f}", f"{len(a)} rows (ESyS) against {len(b)} (Basalt)"))
            continue
        if stem != f and a and len(a[0]) == 7:  # RAW_WITH_ID: by id
            a, b = sorted(a), sorted(b)
        elif stem != f:  # RAW2: no id, rows in each code's own order
            a, b = sorted(a), sorted(b)
        for c in range(len(a[0]) if a else 0):
            g = groups[f"{stem} column {c + 1}"]
            g[0].extend(r[c] for r in a)
            g[1].extend(r[c] for r in b)
            g[2] += len(a)
    for q, (a, b, n) in sorted(groups.items()):
        out.append((q, n, a, b))
    return out


def deviation(a, b):
    span = max(a) - min(a) if a else 0.0
    scale = span if span > 0 else max((abs(v) for v in a), default=0.0) or 1.0
    return max((abs(x - y) for x, y in zip(a, b)), default=0.0) / scale, scale


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scripts", nargs="+", default=["collide", "fall", "settle", "cube_drop", "block_large",
                                                         "slide", "press", "spin", "geo_read", "chain", "pack_box",
                                                         "slope_collapse", "glued", "mesh_drop"])
    ap.add_argument("--workdir", default="out/esys-tutorial")
    ap.add_argument("--tolerance", type=float, default=1e-6)
    ap.add_argument("--build", default=os.path.join(bt.ROOT, "build"), help="the build whose python/ to use")
    ap.add_argument("--pythonpath", help="the folder holding the basalt package (default BUILD/python)")
    ap.add_argument("--timeout", type=float, default=300)
    ap.add_argument("--args", nargs="*", default=[], help="arguments for every script (both codes)")
    ap.add_argument("--spread-args", nargs="*", help="also run ESyS with these arguments (a perturbed run) and "
                    "report how far ESyS spreads from itself; a quantity within that spread passes")
    ap.add_argument("--num-time-steps", type=int, help="run copies of the scripts with setNumTimeSteps(N)")
    ap.add_argument("--spread-replace", nargs=2, metavar=("OLD", "NEW"), help="the perturbed ESyS run takes a copy "
                    "of the script with OLD replaced by NEW")
    ap.add_argument("--esys", default="esysparticle", help="ESyS-Particle's interpreter (default esysparticle)")
    ap.add_argument("--doc", help="write the table into this file between the compare_tutorial markers")
    args = ap.parse_args()

    env_b = dict(os.environ, PYTHONPATH=os.path.abspath(args.pythonpath or os.path.join(args.build, "python")))
    missing = [exe for exe in (args.esys, "mpirun") if shutil.which(exe) is None]
    if missing:
        print(f"ESyS-Particle comparison skipped: {', '.join(missing)} not on PATH "
              "(Debian: apt-get install --no-install-recommends esys-particle); Basalt's runs only")
    rows, times, failed = [], [], False
    for name in args.scripts:
        script = os.path.abspath(name) if name.endswith((".py", ".py.tex")) else os.path.join(SCRIPTS, name + ".py")
        name = re.sub(r"\.py(\.tex)?$", "", os.path.basename(script))
        perturbed = script
        if args.num_time_steps is not None or script.endswith(".tex") or args.spread_replace:
            copies = os.path.abspath(os.path.join(args.workdir, "scripts"))
            original = script
            script = script_copy(original, os.path.join(copies, name), args.num_time_steps)
            perturbed = script if not args.spread_replace else script_copy(
                original, os.path.join(copies, name + "-perturbed"), args.num_time_steps, args.spread_replace)
        dir_b = os.path.abspath(os.path.join(args.workdir, "basalt", name))
        out_b, wall_b, err = run([sys.executable, "-m", "basalt.esys", script, *args.args], dir_b, env_b, args.timeout)
        if err:
            print(f"{name}: Basalt's front end failed: {err}")
            failed = True
            continue
        if missing:
            times.append((name, None, wall_b))
            continue
        dir_e = os.path.abspath(os.path.join(args.workdir, "esys", name))
        out_e, wall_e, err = run(bt.mpirun(2) + [args.esys, script, *args.args], dir_e, bt.esys_env(), args.timeout)
        times.append((name, wall_e, wall_b))
        if err:
            print(f"{name}: ESyS-Particle failed: {err}")
            failed = True
            continue
        spread = {}
        if args.spread_args is not None or args.spread_replace:
            dir_s = dir_e + "-perturbed"
            spread_args = args.args if args.spread_args is None else args.spread_args
            out_s, _, err = run(bt.mpirun(2) + [args.esys, perturbed, *spread_args], dir_s, bt.esys_env(),
                                args.timeout)
            if err:
                print(f"{name}: the perturbed ESyS-Particle run failed: {err}")
                failed = True
                continue
            spread = {q[0]: deviation(q[2], q[3])[0] for q in quantities(name, dir_e, dir_s, out_e, out_s)
                      if len(q) == 4}
        for q in quantities(name, dir_e, dir_b, out_e, out_b):
            if len(q) == 2:
                rows.append((name, q[0], "-", "-", "-", f"**mismatch**: {q[1]}"))
                failed = True
                continue
            quantity, n, a, b = q
            dev, scale = deviation(a, b)
            own = spread.get(quantity)
            verdict = ("ok" if dev <= args.tolerance else
                       "ok: within ESyS's own spread" if own is not None and dev <= own else "**above tolerance**")
            failed |= verdict.startswith("**")
            rows.append((name, quantity, str(n), f"{dev:.1e}", "-" if own is None else f"{own:.1e}", verdict))
    lines = [f"Tolerance: {args.tolerance:g} of each quantity's range over ESyS's rows"
             + (f"; ESyS against itself with arguments {' '.join(args.spread_args)}" if args.spread_args else "")
             + (f"; ESyS against itself with {args.spread_replace[0]!r} replaced by {args.spread_replace[1]!r}"
                if args.spread_replace else "")
             + (f"; setNumTimeSteps({args.num_time_steps})" if args.num_time_steps is not None else "")
             + (f"; script arguments {' '.join(args.args)}" if args.args else "") + ".", "",
             "| script | quantity | rows | max deviation / range | ESyS vs perturbed ESyS | verdict |",
             "| --- | --- | --- | --- | --- | --- |"]
    lines += [f"| {' | '.join(r)} |" for r in rows]
    lines += ["", "| script | ESyS-Particle wall s (mpirun -np 2) | Basalt front end wall s (1 process) | ratio |",
              "| --- | --- | --- | --- |"]
    for name, we, wb in times:
        lines.append(f"| {name} | {'-' if we is None else f'{we:.2f}'} | {wb:.2f} | "
                     f"{'-' if we is None else f'{we / wb:.1f}x'} |")
    table = "\n".join(lines)
    print(table)
    if args.doc and not missing:
        with open(args.doc) as f:
            text = f.read()
        if BEGIN not in text or END not in text:
            sys.exit(f"{args.doc}: no {BEGIN} ... {END} markers")
        head, rest = text.split(BEGIN, 1)
        with open(args.doc, "w") as f:
            f.write(head + BEGIN + "\n" + table + "\n" + END + rest.split(END, 1)[1])
    if failed:
        return 1
    return 3 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
