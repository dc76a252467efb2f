#!/usr/bin/python3
"""partition_study and figure5.py refuse bad input with a message naming the cause and a non-zero exit, and
draw from good input. Usage: cli_check.py PARTITION_STUDY FIGURE5_PY REFERENCE_DIR"""
import os
import subprocess
import sys
import tempfile

exe, fig5, ref = sys.argv[1:4]
cube1 = os.path.join(ref, "cube1.geo")
failures = []


def expect(cmd, rc_nonzero, *needles):
    p = subprocess.run(cmd, capture_output=True, text=True)
    text = p.stdout + p.stderr
    if rc_nonzero != (p.returncode != 0) or any(n not in text for n in needles):
        failures.append(f"{' '.join(cmd)}: exit {p.returncode}, expected {'non-zero' if rc_nonzero else 0} "
                        f"and {needles}; output:\n{text}")
    return text


with tempfile.TemporaryDirectory() as tmp:
    expect([exe, "table", "--geometry", os.path.join(tmp, "missing.geo")], True, "missing.geo")
    expect([exe, "table", "--geometry", cube1, "--max-n", "0"], True, "--max-n")
    expect([exe, "table", "--geometry", cube1, "--max-n", "1", "--csv", os.path.join(tmp, "no", "t.csv")], True,
           os.path.join(tmp, "no", "t.csv"))
    expect([exe, "grid", "--geometry", cube1, "--dims", "2,0,1"], True, "--dims")
    out = expect([exe, "grid", "--geometry", cube1, "--dims", "1,1,1"], False, "rank,cx")
    if "0,0,0,0,8948,0,0,0,0,0" not in out:
        failures.append("grid 1,1,1 on cube1: expected one rank owning 8,948 particles and no ghosts:\n" + out)

    bad = os.path.join(tmp, "bad.csv")
    with open(bad, "w") as f:
        f.write("compute_ranks,stage,seconds_per_10000_steps\n1,none,3.0\n")
    expect(["/usr/bin/python3", fig5, bad, "-o", os.path.join(tmp, "f.png")], True, "io_ranks")
    with open(bad, "w") as f:
        f.write("compute_ranks,io_ranks,stage,seconds_per_10000_steps\n1,0,none,3.0\n1,0,snapshots,4.0\n")
    expect(["/usr/bin/python3", fig5, bad, "-o", os.path.join(tmp, "f.png")], True, "bad.csv:3", "snapshots")
    good = os.path.join(tmp, "good.csv")
    with open(good, "w") as f:
        f.write("compute_ranks,io_ranks,stage,seconds_per_10000_steps\n")
        for p in (1, 2):
            for q in (0, 1):
                for st, t in (("none", 3.0), ("fields", 3.2), ("checkpoint", 5.0), ("both", 5.3)):
                    f.write(f"{p},{q},{st},{t * (1 + 0.1 * p)}\n")
    png = os.path.join(tmp, "f.png")
    expect(["/usr/bin/python3", fig5, good, "-o", png], False, "wrote")
    if not os.path.exists(png) or os.path.getsize(png) < 10000:
        failures.append("figure5.py wrote no PNG from a good CSV")

if failures:
    print("\n\n".join(failures))
    sys.exit(1)
print("ok")
