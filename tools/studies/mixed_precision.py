#!/usr/bin/python3
"""Speed, memory and accuracy of run.precision = "mixed" against double and float (issue 13; results in
docs/stability.md, "Mixed precision", and docs/accuracy.md).

    /usr/bin/python3 tools/studies/mixed_precision.py --build build --work mixed-work [--repeats 3] [--steps 2000]

Cases: the wave scene (scenes/wave.toml) on the 15 mm cube ($BASALT_REFERENCE_DIR/cube1.geo, 8,948
particles) and on the 30 mm cube (cube1 tiled 2x2x2 by tools/bench/wave_tile_geo.py, 71,584), 1 rank.
Settings: double, float, mixed, and mixed without the compensated drift (BASALT_MIXED_COMPENSATION=0: what
the 12 B/particle of remainders buy). Each repeat runs every setting once, one after the other
(interleaved), so a change of the machine's load spreads over all of them. Per setting: the loop's CPU
time ("cpu time of the loop", CPU rather than wall time: the machine is shared), median and range over the
repeats; the bytes per particle of the particle fields basalt-run prints ("fields: ... = N B/particle");
the KE L2 relative error against the double run of the same case (rows where double's KE exceeds 1 % of
its peak, as tools/studies/accuracy_study.py). With --fractions, the accuracy runs repeat at
run.dt_fraction = 0.02 (where float loses small increments v dt) and 0.5.
"""
import argparse
import os
import statistics
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

ROOT = Path(bt.ROOT)
SETTINGS = [("double", "double", {}), ("float", "float", {}), ("mixed", "mixed", {}),
            ("mixed, no compensation", "mixed", {"BASALT_MIXED_COMPENSATION": "0"})]


def run(build, work, geo, tag, precision, env, steps, fraction=None):
    scene = (ROOT / "scenes" / "wave.toml").read_text()
    if fraction:
        scene = scene.replace("dt = 1.0e-3", f"dt_fraction = {fraction}")
    s = work / f"{tag}.toml"
    s.write_text(scene)
    out = work / tag
    r = subprocess.run([bt.binary("basalt-run", build=build), str(s), "--geometry", str(geo), "--steps",
                        str(steps), "--fields-every", "1", "--output", str(out), "--quiet", "--precision",
                        precision], capture_output=True, text=True, env={**os.environ, **env})
    if r.returncode:
        raise SystemExit(f"{tag}: {r.stderr.strip()[-300:]}")
    x = bt.parse_run(r.stdout)
    ke = bt.read_fields(out)["kinetic_energy"]
    return x["cpu_s"], f"{x['field_bytes']} / {x['bytes_per_particle']:.0f}", ke


def l2(ke, ref):
    m = min(len(ke), len(ref))
    peak = max(ref[:m])
    keep = [k for k in range(m) if ref[k] >= 0.01 * peak]
    return (sum((ke[k] - ref[k]) ** 2 for k in keep) / sum(ref[k] ** 2 for k in keep)) ** 0.5


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--work", default="mixed-work")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--cases", default="15,30")
    ap.add_argument("--fractions", action="store_true")
    a = ap.parse_args()
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    cube = Path(bt.reference_cube())
    tiled = work / "cube1-tiled2.geo"
    if "30" in a.cases and not tiled.exists():
        subprocess.run(["/usr/bin/python3", str(ROOT / "tools" / "bench" / "wave_tile_geo.py"), str(cube), "2",
                        str(tiled)], check=True)
    cases = [(c, {"15": cube, "30": tiled}[c]) for c in a.cases.split(",")]
    print("| case | setting | loop CPU (s), median (range) | speed-up vs double (median) | B/particle: fields / solver | "
          "KE L2 rel. vs double |")
    print("| --- | --- | ---: | ---: | ---: | ---: |")
    for case, geo in cases:
        cpu = {name: [] for name, _, _ in SETTINGS}
        bpp, ke = {}, {}
        for rep in range(a.repeats):
            for name, prec, env in SETTINGS:
                c, b, k = run(a.build, work, geo, f"{case}_{name.replace(' ', '_').replace(',', '')}", prec, env,
                              a.steps)
                cpu[name].append(c)
                bpp[name], ke[name] = b, k
        base = statistics.median(cpu["double"])
        for name, _, _ in SETTINGS:
            c = cpu[name]
            med = statistics.median(c)
            print(f"| {case} mm | {name} | {med:.3f} ({min(c):.3f}-{max(c):.3f}) | {base / med:.2f} | {bpp[name]} | "
                  f"{'-' if name == 'double' else format(l2(ke[name], ke['double']), '.2e')} |", flush=True)
    if a.fractions:
        print("\n| dt_fraction | setting | KE L2 rel. vs double (15 mm cube) |")
        print("| ---: | --- | ---: |")
        for frac in (0.02, 0.5):
            res = {name: run(a.build, work, cube, f"f{frac}_{name.replace(' ', '_').replace(',', '')}", prec, env,
                             a.steps, frac)[2] for name, prec, env in SETTINGS}
            for name, _, _ in SETTINGS[1:]:
                print(f"| {frac} | {name} | {l2(res[name], res['double']):.2e} |", flush=True)


if __name__ == "__main__":
    main()
