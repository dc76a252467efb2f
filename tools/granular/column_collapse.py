#!/usr/bin/python3
"""Granular column collapse: runout against aspect ratio (scenes/column-collapse.toml).

Packs a column L x W x H (H = a L) of spheres (radii 0.4-0.6, unit mean diameter d) for each
aspect ratio a, runs scenes/column-collapse.toml on it until the deposit has stopped, measures the
final runout L_inf from the last checkpoint and fits (L_inf - L)/L against a.

Runout measures (all from the particle centres' x, back wall at x = 0):
  front  : the front of the connected deposit: sort the centres' x; walking from the back wall, the
           first gap wider than one diameter (1.0) in this projection ends the deposit (grains rolling
           away alone beyond it are not counted). This is L_inf used for the fit.
  p95, p99, max : percentiles of x of all centres (the `runout` field saver's percentile).
Stopping: the run lasts T = 20 + H time units (sqrt(d/g)); the front is also measured at 3/4 of T,
and the kinetic energy at the end is compared with its peak (fields.csv); both are written.

Fit: least squares of log((L_inf - L)/L) against log a for a >= 1, slope with its standard error;
slope of (L_inf - L)/L against a (through the origin) for a <= 2.

  /usr/bin/python3 tools/granular/column_collapse.py            # a = 0.5 1 2 3 4 6 8
  /usr/bin/python3 tools/granular/column_collapse.py --quick    # a = 0.5 1 2 4
Writes docs/data/column-collapse/runout.csv, fit.csv, docs/img/column_collapse_runout.png and a
picture of the a = 4 deposit (--quick or --tag T: the same names with _quick or _T appended);
the runs go to out/column-collapse/ (not committed).
"""
import argparse
import concurrent.futures as cf
import csv
import math
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

ROOT = bt.ROOT
DT = 0.0025  # must match scenes/column-collapse.toml run.dt


def bindir(args):
    for b in (args.bin, bt.bin_dir()):
        if b and os.path.exists(os.path.join(b, "basalt-run")):
            return b
    sys.exit("basalt-run not found: give --bin")


def front(x, gap=1.0):
    xs = np.sort(x)
    g = np.diff(xs)
    i = np.where(g > gap)[0]
    return xs[i[0]] if len(i) else xs[-1]


def measure(ckpt):
    x = bt.read_h5(ckpt, "particles/position")[0][:, 0]
    return dict(front=front(x), p95=np.percentile(x, 95), p99=np.percentile(x, 99), max=x.max(), n=len(x))


def run_one(a, args, b):
    L, W = args.L, args.W
    H = a * L
    d = os.path.join(args.out, f"a{a:g}")
    os.makedirs(d, exist_ok=True)
    geo = os.path.join(d, "column.h5")
    if not os.path.exists(geo):
        subprocess.run([os.path.join(b, "basalt-pack"), "box", "--size", f"{L:g},{W:g},{H:g}", "--rmin", "0.4",
                        "--rmax", "0.6", "--no-bonds", "--seed", str(args.seed), "-o", geo, "-q"], check=True)
    T = 20.0 + H
    steps = int(math.ceil(T / DT / 4)) * 4
    out = os.path.join(d, "run")
    last = os.path.join(out, f"ckpt_{steps:06d}.h5")
    if not os.path.exists(last):
        subprocess.run([os.path.join(b, "basalt-run"), args.scene,
                        "--geometry", geo, "--output", out, "--steps", str(steps),
                        "--checkpoint-every", str(steps // 4), "--quiet"], check=True,
                       stdout=open(os.path.join(d, "log.txt"), "w"), stderr=subprocess.STDOUT)
    m = measure(last)
    m34 = measure(os.path.join(out, f"ckpt_{3 * steps // 4:06d}.h5"))
    ke = bt.read_fields(out)["kinetic_energy"]
    return dict(a=a, L=L, W=W, H=H, n=m["n"], T=T, steps=steps, front=m["front"], front_3T4=m34["front"],
                p95=m["p95"], p99=m["p99"], max=m["max"], ke_end_over_peak=ke[-1] / max(ke),
                norm_runout=(m["front"] - L) / L)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="a = 0.5 1 2 4 only")
    ap.add_argument("--aspect", type=float, nargs="*", help="aspect ratios (default 0.5 1 2 3 4 6 8)")
    ap.add_argument("--L", type=float, default=10.0)
    ap.add_argument("--W", type=float, default=8.0, help="must match the side wall in the scene")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--bin", help="folder with basalt-pack, basalt-run, basalt-view")
    ap.add_argument("--out", default=os.path.join(ROOT, "out/column-collapse"))
    ap.add_argument("--data", default=os.path.join(ROOT, "docs/data/column-collapse"))
    ap.add_argument("--img", default=os.path.join(ROOT, "docs/img"))
    ap.add_argument("--no-render", action="store_true")
    ap.add_argument("--rot-damping", type=float, help="run with this rotational_damping viscosity instead of the scene's")
    ap.add_argument("--tag", default="", help="suffix of the run folder and the csv/png names (variants)")
    args = ap.parse_args()
    aspects = args.aspect or ([0.5, 1, 2, 4] if args.quick else [0.5, 1, 2, 3, 4, 6, 8])
    b = bindir(args)
    if args.quick and not args.tag:
        args.tag = "quick"  # never overwrite the full study's files
    sfx = f"_{args.tag}" if args.tag else ""
    args.out = args.out + sfx
    args.scene = os.path.join(ROOT, "scenes/column-collapse.toml")
    if args.rot_damping is not None:
        import re
        os.makedirs(args.out, exist_ok=True)
        txt = open(args.scene).read()
        txt, n = re.subn(r'(type = "rotational_damping"\nviscosity = )[0-9.eE+-]+', rf"\g<1>{args.rot_damping!r}", txt)
        assert n == 1, "rotational_damping block not found in the scene"
        args.scene = os.path.join(args.out, "scene.toml")
        open(args.scene, "w").write(txt)
    # biggest first so the two workers finish together
    with cf.ThreadPoolExecutor(args.jobs) as ex:
        res = list(ex.map(lambda a: run_one(a, args, b), sorted(aspects, reverse=True)))
    res.sort(key=lambda r: r["a"])
    os.makedirs(args.data, exist_ok=True)
    keys = list(res[0].keys())
    with open(os.path.join(args.data, f"runout{sfx}.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, keys)
        w.writeheader()
        for r in res:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
    for r in res:
        print(f"a = {r['a']:g}: N = {r['n']}, T = {r['T']:g}, L_inf = {r['front']:.2f} (3T/4: {r['front_3T4']:.2f}), "
              f"(L_inf-L)/L = {r['norm_runout']:.3f}, p95 {r['p95']:.1f} p99 {r['p99']:.1f} max {r['max']:.1f}, "
              f"KE end/peak {r['ke_end_over_peak']:.2e}")
    A = np.array([r["a"] for r in res])
    Y = np.array([r["norm_runout"] for r in res])
    fits = []
    for lo in (1, 2, 4):
        sel = A >= lo
        if sel.sum() >= 2:
            if sel.sum() > 2:
                p, cov = np.polyfit(np.log(A[sel]), np.log(Y[sel]), 1, cov=True)
                se = math.sqrt(cov[0, 0])
            else:  # two points: no scatter, no error
                p, se = np.polyfit(np.log(A[sel]), np.log(Y[sel]), 1), float("nan")
            fits.append((f"power_a_ge_{lo}", int(sel.sum()), p[0], se, math.exp(p[1])))
    for i in range(len(A) - 1):  # local exponents between neighbours
        s = math.log(Y[i + 1] / Y[i]) / math.log(A[i + 1] / A[i])
        fits.append((f"local_{A[i]:g}_{A[i + 1]:g}", 2, s, float("nan"), Y[i] / A[i] ** s))
    small = A <= 2
    if small.sum() >= 1:
        k = float(np.sum(A[small] * Y[small]) / np.sum(A[small] ** 2))
        fits.append(("linear_a_le_2", int(small.sum()), k, float("nan"), 0.0))
    with open(os.path.join(args.data, f"fit{sfx}.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["fit", "points", "exponent_or_slope", "std_error", "prefactor"])
        for row in fits:
            w.writerow([row[0], row[1], f"{row[2]:.4g}", f"{row[3]:.3g}", f"{row[4]:.4g}"])
            print(f"fit {row[0]} ({row[1]} points): {row[2]:.3f} +- {row[3]:.3f}, prefactor {row[4]:.3g}")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    ax.loglog(A, Y, "ko", label="Basalt, connected front")
    ax.loglog(A, [(r["p99"] - r["L"]) / r["L"] for r in res], "s", mfc="none", color="0.5", label="99th percentile of x")
    aa = np.linspace(0.4, max(A) * 1.2, 50)
    for name, n, s, se, c in fits:
        if name.startswith("power_a_ge_1"):
            ax.loglog(aa[aa >= 1], c * aa[aa >= 1] ** s, "k-", label=f"fit a>=1: a^{s:.2f}±{se:.2f}")
    ax.loglog(aa, 1.2 * aa, "b--", lw=0.8, label="1.2 a (channel, a<3)")
    ax.loglog(aa[aa >= 3], 1.9 * aa[aa >= 3] ** (2 / 3), "g:", lw=1, label="1.9 a^(2/3) (channel, a>3)")
    ax.set_xlabel("aspect ratio a = H/L")
    ax.set_ylabel("(L_inf - L)/L")
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    os.makedirs(args.img, exist_ok=True)
    fig.savefig(os.path.join(args.img, f"column_collapse_runout{sfx}.png"), dpi=120)
    if not args.no_render:
        r = res[-1] if args.quick else [q for q in res if q["a"] == 4][0] if 4 in A else res[-1]
        ck = os.path.join(args.out, f"a{r['a']:g}", "run", f"ckpt_{r['steps']:06d}.h5")
        png = os.path.join(args.img, f"column_collapse_deposit_a{r['a']:g}{sfx}.png")
        subprocess.run(["xvfb-run", "-a", os.path.join(b, "basalt-view"), "render", ck, "-o", png,
                        "--view", "-y", "--color", "displacement", "--reference",
                        os.path.join(args.out, f"a{r['a']:g}", "column.h5"), "--size", "2000x450", "-q"])


if __name__ == "__main__":
    main()
