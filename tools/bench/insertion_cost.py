"""What pouring particles in costs (issue 44, docs/BENCHMARKS.md "Particles in and out"): a pile of about
100,000 frictional spheres (basalt.pack.box, radii 0.4-0.5, under gravity on a floor) takes 1,000 new spheres
per event (Simulation.insert: candidates, the owners' overlap checks, the agreement, a rebuild and the forces),
and loses 1,000 per deletion (Simulation.delete). Both are set against what the run pays anyway: one step, and
one rebuild between steps (a deletion of an empty region: the rebuild and the forces alone). Times are the
slowest rank's, medians over the events; 1 and 2 ranks, one after the other in the same run of this script.

    /usr/bin/python3 tools/bench/insertion_cost.py [--size 47] [--events 5] [--count 1000] [--ranks 1 2] [--json out.json]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402

CHILD = r"""
import json, sys, time, basalt
geo, out, size, events, count, steps = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6])
scene = {
    "geometry": {"file": geo},
    "particles": {"rotation": True},
    "run": {"dt": 2e-3, "skin": 0.1},
    "interactions": [{"type": "rot_friction", "K": 1000.0, "Ks": 500.0, "mu": 0.5, "mu_dynamic": 0.4}],
    "walls": [{"name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1], "K": 1000.0}],
    "body_forces": [{"type": "gravity", "acceleration": [0, 0, -1.0]}],
    "output": {"directory": out},
}
sim = basalt.Simulation(scene)

def timed(f):
    t = time.perf_counter()
    r = f()
    return sim.max(time.perf_counter() - t), r

n0 = sim.total_particles
sim.run(20)
step_s = timed(lambda: sim.run(steps))[0] / steps
rebuild_s, ins_s, del_s, got, gone = [], [], [], [], []
for k in range(events):
    # An empty region: the rebuild and the forces a deletion or insertion brings, with nothing to do.
    rebuild_s.append(timed(lambda: sim.delete(box=((1e6, 1e6, 1e6), (1e6 + 1, 1e6 + 1, 1e6 + 1))))[0])
    # Each event into its own slab above the pile (2.2 diameters high: room for 1,000 and more).
    lo, hi = (0.5, 0.5, size + 2 + 3 * k), (size - 0.5, size - 0.5, size + 4.2 + 3 * k)
    t, n = timed(lambda: sim.insert(box=(lo, hi), radius=(0.4, 0.5), count=count, seed=k))
    ins_s.append(t); got.append(n)
    sim.run(steps)
    t, n = timed(lambda: sim.delete(box=(lo, (hi[0], hi[1], hi[2] + 1))))
    del_s.append(t); gone.append(n)
if sim.rank == 0:
    print("RESULT " + json.dumps({"particles": n0, "step_s": step_s, "rebuild_s": rebuild_s, "insert_s": ins_s,
                                  "delete_s": del_s, "inserted": got, "deleted": gone}))
sim.close()
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=float, default=47.0, help="the packed box's edge (47: about 105,000 spheres)")
    ap.add_argument("--events", type=int, default=5)
    ap.add_argument("--count", type=int, default=1000)
    ap.add_argument("--steps", type=int, default=50, help="steps timed, and steps between an insert and its deletion")
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--pythonpath", default=bt.repo_path("build", "python"))
    ap.add_argument("--json")
    args = ap.parse_args()
    pythonpath = os.path.abspath(args.pythonpath)
    sys.path.insert(0, pythonpath)
    import basalt

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        geo = os.path.join(tmp, "pile.h5")
        g = basalt.pack.box(size=(args.size,) * 3, rmin=0.4, rmax=0.5, seed=1, no_bonds=True)
        g.write(geo)
        script = os.path.join(tmp, "child.py")
        with open(script, "w") as f:
            f.write(CHILD)
        for ranks in args.ranks:
            cmd = [sys.executable, script, geo, os.path.join(tmp, f"np{ranks}"), str(args.size), str(args.events),
                   str(args.count), str(args.steps)]
            if ranks > 1:
                cmd = bt.mpirun(ranks) + cmd
            p = subprocess.run(cmd, capture_output=True, text=True, env=bt.mpi_env(ranks=ranks, PYTHONPATH=pythonpath))
            if p.returncode != 0:
                raise SystemExit(f"{' '.join(cmd)} failed:\n{p.stdout}\n{p.stderr}")
            r = json.loads(p.stdout.split("RESULT ", 1)[1].splitlines()[0])
            med = {k: statistics.median(r[k]) for k in ("rebuild_s", "insert_s", "delete_s")}
            row = {"ranks": ranks, **r, "median_s": med,
                   "insert_over_step": med["insert_s"] / r["step_s"],
                   "insert_over_rebuild": med["insert_s"] / med["rebuild_s"],
                   "delete_over_rebuild": med["delete_s"] / med["rebuild_s"],
                   "insert_us_per_particle": 1e6 * (med["insert_s"] - med["rebuild_s"]) / statistics.median(r["inserted"])}
            rows.append(row)
            print(f"np {ranks}: {r['particles']} particles; a step {1e3 * r['step_s']:.2f} ms, a rebuild between steps "
                  f"{1e3 * med['rebuild_s']:.1f} ms; inserting {statistics.median(r['inserted']):.0f} "
                  f"{1e3 * med['insert_s']:.1f} ms ({row['insert_over_step']:.1f} steps, "
                  f"{row['insert_over_rebuild']:.2f}x a rebuild, {row['insert_us_per_particle']:.1f} us per particle "
                  f"beyond it); deleting {statistics.median(r['deleted']):.0f} {1e3 * med['delete_s']:.1f} ms "
                  f"({row['delete_over_rebuild']:.2f}x a rebuild)", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"host": bt.host_summary() if hasattr(bt, "host_summary") else os.uname().nodename,
                       "time": time.strftime("%Y-%m-%d %H:%M"), "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
