#!/usr/bin/python3
"""run.precision = "mixed" end to end on the wave scene (scenes/wave.toml) and cube1.geo, 2,000 steps, 1 rank:

  1. offset independence: the geometry and the wall shifted by D = 1e6 length units give the kinetic-energy
     curve of the unshifted run in mixed within 1e-4 (L2 relative); float misses that already at D = 100
     and refuses D = 1e6 (its load check: the strain resolution there is ~0.3);
  2. accuracy: mixed against double, KE L2 relative error below 1e-3 at the scene's dt and at
     run.dt_fraction = 0.02 (where float's drift loses small increments v dt).

    mixed_precision_check.py BASALT_RUN GEOMETRY WORKDIR
Prints every number it checks; exits 1 when a check fails.
"""
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
STEPS = 2000


def shifted_geo(src, d, out):
    lines = Path(src).read_text().split("\n")
    i0 = lines.index("Simple") + 2
    n = int(lines[i0 - 1])
    for k, line in enumerate(lines):
        if line.startswith("BoundingBox"):
            lines[k] = "BoundingBox " + " ".join("%.17g" % (float(x) + d) for x in line.split()[1:])
    for k in range(i0, i0 + n):
        p = lines[k].split()
        lines[k] = " ".join(["%.17g" % (float(p[j]) + d) for j in range(3)] + p[3:])
    out.write_text("\n".join(lines))


def run(basalt, geo_src, work, d, precision, fraction=None, dt=None, out_text=None):
    tag = f"{precision}_{d:g}_{fraction or dt or 'dt'}"
    g, s, o = work / f"g{d:g}.geo", work / f"{tag}.toml", work / tag
    if not g.exists():
        shifted_geo(geo_src, d, g)
    scene = (ROOT / "scenes" / "wave.toml").read_text()
    scene = scene.replace("point = [0.0, 0.0, 0.0]", f"point = [{d:.17g}, {d:.17g}, {d:.17g}]")
    if fraction:
        scene = scene.replace("dt = 1.0e-3", f"dt_fraction = {fraction}")
    elif dt:
        scene = scene.replace("dt = 1.0e-3", f"dt = {dt}")
    s.write_text(scene)
    r = subprocess.run([basalt, str(s), "--geometry", str(g), "--steps", str(STEPS), "--output", str(o),
                        "--quiet", "--precision", precision], capture_output=True, text=True)
    if out_text is not None:
        out_text.append(r.stdout + r.stderr)
    if r.returncode:
        return None, r.stderr.strip().split("\n")[-1]
    rows = (o / "fields.csv").read_text().split("\n")
    col = rows[0].split(",").index("kinetic_energy")
    return [float(line.split(",")[col]) for line in rows[1:] if line], ""


def l2(ke, ref):
    m = min(len(ke), len(ref))
    peak = max(ref[:m])
    keep = [k for k in range(m) if ref[k] >= 0.01 * peak]  # as tools/studies/accuracy_study.py
    num = sum((ke[k] - ref[k]) ** 2 for k in keep)
    return (num / sum(ref[k] ** 2 for k in keep)) ** 0.5


def max_rel(ke, ref):
    m = min(len(ke), len(ref))
    return max(abs(ke[k] - ref[k]) for k in range(m)) / max(ref[:m])


def main():
    basalt, geo, work = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    work.mkdir(parents=True, exist_ok=True)
    ok = True

    def check(name, value, limit):
        nonlocal ok
        good = value < limit
        ok = ok and good
        print(f"{'PASS' if good else 'FAIL'}: {name} = {value:.3e} (limit {limit:g})")

    ref, msg = run(basalt, geo, work, 0.0, "double")
    mixed0, msg0 = run(basalt, geo, work, 0.0, "mixed")
    mixed6, msg6 = run(basalt, geo, work, 1e6, "mixed")
    if ref is None or mixed0 is None or mixed6 is None:
        print(f"FAIL: a run failed: {msg or msg0 or msg6}")
        return 1
    # L2 over the curve: a single step's difference is float's rounding noise grown by the wave's
    # sensitivity (max over steps 1.3e-4, the same as mixed against double's 1.2e-4).
    check("mixed, D = 1e6 against D = 0: KE L2", l2(mixed6, mixed0), 1e-4)
    print(f"(max |KE difference| / max KE: {max_rel(mixed6, mixed0):.3e}; mixed against double: "
          f"{max_rel(mixed0, ref):.3e})")
    check("mixed, D = 1e6 against double D = 0: KE L2", l2(mixed6, ref), 1e-3)
    check("mixed against double at run.dt = 1e-3: KE L2", l2(mixed0, ref), 1e-3)
    # Float fails the same check already at D = 100 (the largest offset its load check lets run, warning).
    float0, _ = run(basalt, geo, work, 0.0, "float")
    float2, msgf = run(basalt, geo, work, 100.0, "float")
    if float0 is None or float2 is None:
        print(f"FAIL: a float run failed: {msgf}")
        return 1
    f2 = l2(float2, float0)
    print(f"{'PASS' if f2 > 1e-4 else 'FAIL'}: float, D = 100 against D = 0: KE L2 = {f2:.3e} (must exceed 1e-4: "
          "float rounds positions to their distance from the coordinate origin)")
    ok = ok and f2 > 1e-4
    float6, msgf = run(basalt, geo, work, 1e6, "float")
    if float6 is None:
        print(f"float at D = 1e6 is refused, as it must be: {msgf[:160]}")
    else:
        print(f"FAIL: float ran at D = 1e6 (KE L2 against double {l2(float6, ref):.3e})")
        ok = False
    # The same dt for the three: 0.02 of double's critical step (float's estimate of the step is ~0.5 %
    # lower, its force differences being rounded: compared at their own dt_fraction the curves would
    # differ by that change of dt, not by the precision).
    text = []
    run(basalt, geo, work, 0.0, "double", 0.02, out_text=text)
    m = re.search(r"time step: dt = ([0-9.eE+-]+) ", text[0])
    if not m:
        print("FAIL: no 'time step: dt = ...' line in the double run's output")
        return 1
    dt = m.group(1)
    ref_s, msg = run(basalt, geo, work, 0.0, "double", dt=dt)
    mixed_s, msg2 = run(basalt, geo, work, 0.0, "mixed", dt=dt)
    float_s, msg3 = run(basalt, geo, work, 0.0, "float", dt=dt)
    if ref_s is None or mixed_s is None or float_s is None:
        print(f"FAIL: a run at dt_fraction 0.02 failed: {msg or msg2 or msg3}")
        return 1
    check("mixed against double at dt = 0.02 x double's critical step: KE L2", l2(mixed_s, ref_s), 1e-3)
    print(f"(float against double at the same dt: KE L2 = {l2(float_s, ref_s):.3e})")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
