#!/usr/bin/python3
"""The seed paper's scaling study at this machine's scale (docs/paper-study.md).

Steps (each can be skipped; results go to --data, default docs/data/paper_study):
  table     partition_study table: Table 2 (1x1x1 .. 10x10x10 subdomains of 15 mm), cube1.geo tiled
            -> table2.csv, table2.md
  packed    (not by default) the same for n <= --pack with cubes packed whole by basalt::packer
            -> table2_packed.csv, table2_packed.md
  pingpong  mpirun -np 2 partition_study pingpong -> pingpong.csv (latency, bandwidth, allreduce)
  runs      basalt-run scenes/wave.toml on the 15 mm cube cube1.geo at P = 1, 2 compute ranks and Q = 0, 1 I/O
            ranks for the four output stages (none, field saver, checkpoint every 100 steps, both), and on
            basalt-pack's seed-7 cube (no output, Q = 0); --repeats each, interleaved -> runs.csv (every run
            with basalt-run's timing summary and CPU time), stages.csv (Figure 5 input, see figure5.py)
  weak      (not by default) Figure 5 with one 15 mm cube per compute rank: cube1.geo twice side by side at
            P = 2, the four stages, Q = 0, 1 -> stages_weak.csv (needs stages.csv from runs)
  model     weak-scaling projection to 1000 ranks from the measured costs -> model.csv, model.md,
            docs/img/weak_scaling.png
Run from the worktree root with the build in build/:
  source scripts/mpi-env.sh && /usr/bin/python3 tools/bench/paper_study.py --steps 3000 --repeats 3
"""
import argparse
import csv
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

ROOT = bt.ROOT

# The paper (Weatherley et al. 2010, Tables 1-2): SGI cluster, Xeon L5520, 10,000 steps.
PAPER_STEPS = 10000
PAPER_POINTS = {27: 1104.5, 1000: 1617.5}  # workers -> seconds, no output
PAPER_PARTICLES = {27: 241540, 1000: 8700121}
# Assumed interconnect of a 2010 cluster (InfiniBand QDR class); not measured, stated in the docs.
CLUSTER_LATENCY_S = 3e-6
CLUSTER_BANDWIDTH_BPS = 2.5e9



def sh(cmd, **kw):
    print("+", " ".join(cmd), flush=True)
    return subprocess.run(cmd, check=True, text=True, capture_output=True, **kw)


def mpirun(np):
    # --bind-to none: on this shared 2-core machine a rank pinned to a core cannot move to the other core
    # when a foreign job occupies its own; pinned 2-rank runs were 2-4x slower (docs/paper-study.md).
    return ["mpirun", "-np", str(np), "--bind-to", "none"]


# ---------------------------------------------------------------------------------------------- table
def step_table(a):
    out = sh([a.bin("partition_study"), "table", "--geometry", a.cube1, "--max-n", str(a.max_n), "--csv",
              os.path.join(a.data, "table2.csv")])
    with open(os.path.join(a.data, "table2.md"), "w") as f:
        f.write(out.stdout)
    print(out.stdout)


def step_packed(a):
    """Table 2 again, with the cubes n <= --pack packed as one piece by basalt::packer (GenGeo-like power law),
    so that bonds cross the subdomain faces as in the paper's packings."""
    out = sh([a.bin("partition_study"), "table", "--geometry", a.cube1, "--max-n", str(a.pack), "--pack",
              str(a.pack), "--csv", os.path.join(a.data, "table2_packed.csv")])
    with open(os.path.join(a.data, "table2_packed.md"), "w") as f:
        f.write(out.stdout)
    print(out.stdout)


def step_pingpong(a):
    out = sh(mpirun(2) + [a.bin("partition_study"), "pingpong", "--csv", os.path.join(a.data, "pingpong.csv")])
    print(out.stdout)


def read_pingpong(a):
    with open(os.path.join(a.data, "pingpong.csv")) as f:
        for line in f:
            if line.startswith("#"):
                kv = dict(x.split("=") for x in line[1:].split())
                # The best trial: the link's capability when both ranks are scheduled (this machine is shared).
                return float(kv["latency_best_s"]), float(kv["bandwidth_best_Bps"]), float(kv["allreduce_best_s"])
    raise SystemExit("pingpong.csv has no summary line")


# ----------------------------------------------------------------------------------------------- runs
def parse_run(stdout):
    r = bt.parse_run(stdout)
    if "loop_s" not in r or "particles" not in r:
        raise SystemExit("cannot read basalt-run's summary:\n" + stdout)
    # (the "time per step:" line's maxima over the ranks; at several ranks a "time per step by rank" line follows)
    parts = {k: v[0] for k, v in r.get("phases", {}).items()}
    return {"particles": r["particles"], "bonds": r["bonds"], "ranks": r["compute_ranks"],
            "steps": r["loop_steps"], "loop_s": r["loop_s"], "startup_s": r["startup_s"],
            "rebuilds": r["rebuilds"], "forces_ms": parts["forces"], "neighbour_ms": parts["neighbour search"],
            "comm_ms": parts["communication"], "integration_ms": parts["integration"], "output_ms": parts["output"]}


def ensure_packed(a):
    if not os.path.exists(a.packed):
        os.makedirs(os.path.dirname(a.packed), exist_ok=True)
        sh([a.bin("basalt-pack"), "box", "--size", "15,15,15", "--rmin", "0.2", "--rmax", "1.0", "--seed", "7",
            "-o", a.packed, "--quiet"])


# The paper's four output stages as basalt-run options (the scene's own field saver, kinetic energy, is
# switched by --fields-every; checkpoints are HDF5 files written by the compute ranks (Q = 0) or by the
# I/O rank (Q = 1); no VTK frames).
STAGE_ARGS = {
    "none": ["--fields-every", "0", "--checkpoint-every", "0"],
    "fields": ["--fields-every", "1", "--checkpoint-every", "0"],
    "checkpoint": ["--fields-every", "0", "--checkpoint-every", "100"],
    "both": ["--fields-every", "1", "--checkpoint-every", "100"],
}


def step_runs(a):
    ensure_packed(a)
    tmp = tempfile.mkdtemp(prefix="paper-study-")
    rows = []
    configs = [("cube1.geo", a.cube1, stage, p, q) for stage in STAGE_ARGS for p in (1, 2) for q in (0, 1)]
    configs += [("basalt-pack seed 7", a.packed, "none", p, 0) for p in (1, 2)]
    scene = os.path.join(ROOT, "scenes", "wave.toml")
    try:
        # Interleave the configurations within each repeat so that machine noise spreads over all of them.
        for rep in range(a.repeats):
            for gname, gpath, stage, p, q in configs:
                out_dir = os.path.join(tmp, "out")
                shutil.rmtree(out_dir, ignore_errors=True)
                cmd = (["/usr/bin/time", "-f", "CPU %U %S"] + mpirun(p + q) +
                       [a.bin("basalt-run"), scene, "--geometry", os.path.abspath(gpath), "--steps", str(a.steps),
                        "--output", out_dir, "--quiet", "--frames-every", "0", "--io-ranks", str(q)] +
                       STAGE_ARGS[stage])
                for attempt in range(3):
                    print("+", " ".join(cmd), flush=True)
                    out = subprocess.run(cmd, text=True, capture_output=True)
                    if out.returncode == 0:
                        break
                    # Keep every failure (it is a finding) and try again, at most twice.
                    with open(os.path.join(a.data, "failures.log"), "a") as f:
                        f.write(f"$ {' '.join(cmd)}\nexit {out.returncode}\n{out.stdout}\n{out.stderr}\n\n")
                    print(f"  FAILED (exit {out.returncode}), see failures.log", flush=True)
                    shutil.rmtree(out_dir, ignore_errors=True)
                else:
                    raise SystemExit("basalt-run failed 3 times: " + " ".join(cmd))
                r = parse_run(out.stdout)
                cpu = re.search(r"CPU ([0-9.]+) ([0-9.]+)", out.stderr)
                r["cpu_user_s"], r["cpu_sys_s"] = float(cpu.group(1)), float(cpu.group(2))
                r.update({"geometry": gname, "stage": stage, "io_ranks": q, "repeat": rep})
                print(f"  {gname:20s} {stage:10s} P={p} Q={q} loop {r['loop_s']:.3f} s  comm {r['comm_ms']:.4f} "
                      f"ms/step  cpu {r['cpu_user_s']:.2f}+{r['cpu_sys_s']:.2f} s", flush=True)
                rows.append(r)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    keys = ["geometry", "stage", "ranks", "io_ranks", "repeat", "particles", "bonds", "steps", "loop_s",
            "startup_s", "rebuilds", "forces_ms", "neighbour_ms", "comm_ms", "integration_ms", "output_ms",
            "cpu_user_s", "cpu_sys_s"]
    with open(os.path.join(a.data, "runs.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    # Figure 5 input: one row per run, time scaled to the paper's 10,000 steps.
    with open(os.path.join(a.data, "stages.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["geometry", "compute_ranks", "io_ranks", "stage", "repeat", "particles", "steps",
                    "loop_seconds", "seconds_per_10000_steps"])
        for r in rows:
            w.writerow([r["geometry"], r["ranks"], r["io_ranks"], r["stage"], r["repeat"], r["particles"],
                        r["steps"], r["loop_s"], r["loop_s"] * PAPER_STEPS / r["steps"]])


def tile_geo(src, dims, dst):
    """Copies of a .geo packing side by side (dims = copies along x, y, z; ids offset per copy; bonds only
    within copies): weak scaling, one 15 mm cube per compute rank."""
    with open(src) as f:
        lines = f.read().split("\n")
    box = [float(v) for v in lines[1].split()[1:7]]
    side = [box[3] - box[0], box[4] - box[1], box[5] - box[2]]
    i = lines.index("BeginParticles")
    parts = [l.split() for l in lines[i + 3:i + 3 + int(lines[i + 2])]]
    j = lines.index("BeginConnect", i)
    bonds = [l.split() for l in lines[j + 2:j + 2 + int(lines[j + 1])]]
    stride = max(int(p[4]) for p in parts) + 1
    out_p, out_b = [], []
    k = 0
    for ix in range(dims[0]):
        for iy in range(dims[1]):
            for iz in range(dims[2]):
                off = k * stride
                for x, y, z, r, pid, tag in parts:
                    out_p.append(f"{float(x) + ix * side[0]!r} {float(y) + iy * side[1]!r} "
                                 f"{float(z) + iz * side[2]!r} {r} {int(pid) + off} {tag}")
                for a_, b_, t in bonds:
                    out_b.append(f"{int(a_) + off} {int(b_) + off} {t}")
                k += 1
    hi = [box[d] + dims[d] * side[d] for d in range(3)]
    with open(dst, "w") as f:
        f.write("LSMGeometry 1.2\n")
        f.write(f"BoundingBox {box[0]} {box[1]} {box[2]} {hi[0]} {hi[1]} {hi[2]}\n")
        f.write("PeriodicBoundaries 0 0 0\nDimension 3D\nBeginParticles\nSimple\n")
        f.write(f"{len(out_p)}\n" + "\n".join(out_p) + "\nEndParticles\nBeginConnect\n")
        f.write(f"{len(out_b)}\n" + "\n".join(out_b) + "\nEndConnect\n")


def step_weak(a):
    """Figure 5 as the paper drew it: one 15 mm cube per compute rank. P = 2 runs cube1.geo twice side by side
    (2 x 1 x 1, 17,896 particles) with the four stages and Q = 0, 1 -> stages_weak.csv (with the P = 1 rows of
    stages.csv: the same cube1 on 1 rank)."""
    geo = os.path.join(os.path.dirname(a.packed), "cube1_2x1x1.geo")
    os.makedirs(os.path.dirname(geo), exist_ok=True)
    tile_geo(a.cube1, (2, 1, 1), geo)
    tmp = tempfile.mkdtemp(prefix="paper-study-")
    rows = [r for r in read_csv(os.path.join(a.data, "stages.csv"))
            if r["geometry"] == "cube1.geo" and r["compute_ranks"] == "1"]
    for r in rows:
        r["geometry"] = "15 mm cube per compute rank"
    scene = os.path.join(ROOT, "scenes", "wave.toml")
    try:
        for rep in range(a.repeats):
            for stage in STAGE_ARGS:
                for q in (0, 1):
                    out_dir = os.path.join(tmp, "out")
                    shutil.rmtree(out_dir, ignore_errors=True)
                    cmd = (mpirun(2 + q) + [a.bin("basalt-run"), scene, "--geometry", geo, "--steps", str(a.steps),
                                            "--output", out_dir, "--quiet", "--frames-every", "0", "--io-ranks",
                                            str(q), "--dims", "2,1,1"] + STAGE_ARGS[stage])
                    for attempt in range(3):
                        print("+", " ".join(cmd), flush=True)
                        out = subprocess.run(cmd, text=True, capture_output=True)
                        if out.returncode == 0:
                            break
                        with open(os.path.join(a.data, "failures.log"), "a") as f:
                            f.write(f"$ {' '.join(cmd)}\nexit {out.returncode}\n{out.stdout}\n{out.stderr}\n\n")
                    else:
                        raise SystemExit("basalt-run failed 3 times: " + " ".join(cmd))
                    r = parse_run(out.stdout)
                    print(f"  2x cube1 {stage:10s} P=2 Q={q} loop {r['loop_s']:.3f} s", flush=True)
                    rows.append({"geometry": "15 mm cube per compute rank", "compute_ranks": 2, "io_ranks": q,
                                 "stage": stage, "repeat": rep, "particles": r["particles"], "steps": r["steps"],
                                 "loop_seconds": r["loop_s"],
                                 "seconds_per_10000_steps": r["loop_s"] * PAPER_STEPS / r["steps"]})
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    with open(os.path.join(a.data, "stages_weak.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, ["geometry", "compute_ranks", "io_ranks", "stage", "repeat", "particles", "steps",
                               "loop_seconds", "seconds_per_10000_steps"])
        w.writeheader()
        w.writerows(rows)


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


# ---------------------------------------------------------------------------------------------- model
def median_of(rows, key, **match):
    v = [float(r[key]) for r in rows if all(str(r[k]) == str(x) for k, x in match.items())]
    if not v:
        raise SystemExit(f"no runs match {match}")
    return statistics.median(v)


def ghosts_at_np2(a):
    """Mean owned and largest ghost count per rank at 2 ranks on cube1.geo (2x1x1, as MPI_Dims_create
    chooses), from partition_study's replay of the decomposition."""
    out = sh([a.bin("partition_study"), "grid", "--geometry", a.cube1, "--dims", "2,1,1"])
    rows = list(csv.DictReader(out.stdout.splitlines()))
    return statistics.mean(float(r["owned"]) for r in rows), max(float(r["ghosts"]) for r in rows)


def write_costs(a, runs):
    """Medians per configuration of basalt-run's own timing summary -> costs.md."""
    keys = []
    for r in runs:
        k = (r["geometry"], r["stage"], r["ranks"], r["io_ranks"])
        if k not in keys:
            keys.append(k)
    lines = ["| geometry | output stage | P | Q | runs | loop s per 10,000 steps | forces | neighbour search | "
             "communication | integration | output (ms per step) | CPU s (all processes) | rebuilds |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for g, st, p, q in keys:
        sel = [r for r in runs if (r["geometry"], r["stage"], r["ranks"], r["io_ranks"]) == (g, st, p, q)]
        m = lambda k: statistics.median(float(r[k]) for r in sel)
        steps = float(sel[0]["steps"])
        cpu = statistics.median(float(r["cpu_user_s"]) + float(r["cpu_sys_s"]) for r in sel)
        lines.append(f"| {g} | {st} | {p} | {q} | {len(sel)} | {m('loop_s') * PAPER_STEPS / steps:.2f} | "
                     f"{m('forces_ms'):.3f} | {m('neighbour_ms'):.3f} | {m('comm_ms'):.3f} | "
                     f"{m('integration_ms'):.3f} | {m('output_ms'):.3f} | {cpu:.2f} | {m('rebuilds'):.0f} |")
    with open(os.path.join(a.data, "costs.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


GAMMA = 0.2  # work of a ghost relative to an owned particle (assumed; see docs/paper-study.md)


def step_model(a):
    runs = read_csv(os.path.join(a.data, "runs.csv"))
    write_costs(a, runs)
    table = read_csv(os.path.join(a.data, "table2.csv"))
    lat, bw, ar2 = read_pingpong(a)
    g = "cube1.geo"
    sel = [r for r in runs if r["geometry"] == g and r["ranks"] == "1" and r["stage"] == "none" and
           r["io_ranks"] == "0"]
    n1 = int(sel[0]["particles"])
    steps = int(sel[0]["steps"])
    # Compute cost per particle-step on a core of its own: CPU seconds of the 1-rank run (user + sys), the
    # start-up's share removed in proportion to wall time. The wall-clock phases are inflated by the other
    # processes sharing the 2 cores; they are reported too.
    cpu_loop = [(float(r["cpu_user_s"]) + float(r["cpu_sys_s"])) * float(r["loop_s"]) /
                (float(r["loop_s"]) + float(r["startup_s"])) for r in sel]
    c_p = statistics.median(cpu_loop) / (n1 * steps)
    wall_compute = sum(median_of(runs, k, geometry=g, ranks=1, stage="none", io_ranks=0)
                       for k in ("forces_ms", "neighbour_ms", "integration_ms")) * 1e-3
    owned2, ghosts2 = ghosts_at_np2(a)
    comm2 = median_of(runs, "comm_ms", geometry=g, ranks=2, stage="none", io_ranks=0) * 1e-3
    rebuild_rate = median_of(runs, "rebuilds", geometry=g, ranks=1, stage="none", io_ranks=0) / steps
    fields1 = median_of(runs, "output_ms", geometry=g, ranks=1, stage="fields", io_ranks=0) * 1e-3
    fields2 = median_of(runs, "output_ms", geometry=g, ranks=2, stage="fields", io_ranks=0) * 1e-3
    measured = {"particles_1rank": n1, "cpu_s_per_particle_step": c_p,
                "wall_compute_s_per_step_1rank_contended": wall_compute,
                "wall_s_per_particle_step_1rank_contended": wall_compute / n1, "owned_2rank": owned2,
                "ghosts_2rank_max": ghosts2, "wall_comm_s_per_step_2rank": comm2, "rebuilds_per_step": rebuild_rate,
                "latency_s": lat, "bandwidth_Bps": bw, "allreduce2_s": ar2, "fieldsaver_s_per_step_1rank": fields1,
                "fieldsaver_s_per_step_2rank": fields2}

    def project(row, L, B, compute_per_particle, once=False):
        P = int(row["subdomains"])
        owned = float(row["owned_max"])
        ghosts = float(row["ghosts_max"])
        msgs = float(row["messages_max"])
        # Interactions with a ghost end are computed on both ranks (Basalt today), or, once=True, on one of
        # them (half of them on each side, on average) with the reaction sent back to the ghost's owner.
        compute = compute_per_particle * (owned + (GAMMA / 2 if once else GAMMA) * ghosts)
        # Every step: up to 6 blocking sendrecv phases of x, y, z per ghost; the busiest rank's bytes cross.
        comm = msgs * L + float(row["bytes_step_max"]) / B
        # Computing once adds the reverse exchange: the same phases backwards, a force (3 doubles, as many
        # bytes as the positions) per ghost, and the force loop must wait for it before the kick.
        if once:
            comm *= 2
        # At a rebuild (every 1/rebuild_rate steps): migration and ghost build, each a count and a payload
        # message per phase; ghost records of 48 bytes.
        comm += rebuild_rate * (4 * msgs * L + ghosts * 48 / B)
        # One allreduce per step (the largest displacement): ceil(log2 P) latency-bound rounds.
        reduce_ = math.ceil(math.log2(P)) * L if P > 1 else 0.0
        return compute, comm, reduce_

    # The paper's compute speed: the cost per particle-step that makes this model give the paper's 27-worker
    # time (1,104.5 s per 10,000 steps) with the cluster's assumed L, B and Table 2's 27-subdomain row.
    row27 = next(r for r in table if int(r["subdomains"]) == 27)
    _, m27, r27 = project(row27, CLUSTER_LATENCY_S, CLUSTER_BANDWIDTH_BPS, 0.0)
    c_paper = (PAPER_POINTS[27] / PAPER_STEPS - m27 - r27) / (float(row27["owned_max"]) +
                                                            GAMMA * float(row27["ghosts_max"]))
    measured["paper_s_per_particle_step_calibrated"] = c_paper
    rows = []
    for row in table:
        P = int(row["subdomains"])
        c_here, m_here, r_here = project(row, lat, bw, c_p)
        c_cl, m_cl, r_cl = project(row, CLUSTER_LATENCY_S, CLUSTER_BANDWIDTH_BPS, c_p)
        c_pp, m_pp, r_pp = project(row, CLUSTER_LATENCY_S, CLUSTER_BANDWIDTH_BPS, c_paper)
        once_here = sum(project(row, lat, bw, c_p, once=True)) * PAPER_STEPS
        once_cl = sum(project(row, CLUSTER_LATENCY_S, CLUSTER_BANDWIDTH_BPS, c_p, once=True)) * PAPER_STEPS
        # The gamma above which computing once pays: half the cross work saved equals the reverse exchange.
        ghosts = float(row["ghosts_max"])
        rev_here = float(row["messages_max"]) * lat + float(row["bytes_step_max"]) / bw
        rev_cl = float(row["messages_max"]) * CLUSTER_LATENCY_S + float(row["bytes_step_max"]) / CLUSTER_BANDWIDTH_BPS
        gamma_here = 2 * rev_here / (c_p * ghosts) if ghosts else float("inf")
        gamma_cl = 2 * rev_cl / (c_p * ghosts) if ghosts else float("inf")
        rows.append({"n": int(row["n"]), "ranks": P, "particles": int(row["particles"]),
                     "owned_max": float(row["owned_max"]), "ghosts_max": float(row["ghosts_max"]),
                     "bytes_step_max": float(row["bytes_step_max"]), "messages_max": int(float(row["messages_max"])),
                     "here_compute_s": c_here, "here_comm_s": m_here, "here_reduce_s": r_here,
                     "here_T10k_s": (c_here + m_here + r_here) * PAPER_STEPS,
                     "cluster_compute_s": c_cl, "cluster_comm_s": m_cl, "cluster_reduce_s": r_cl,
                     "cluster_T10k_s": (c_cl + m_cl + r_cl) * PAPER_STEPS,
                     "paperspeed_T10k_s": (c_pp + m_pp + r_pp) * PAPER_STEPS,
                     "here_once_T10k_s": once_here, "cluster_once_T10k_s": once_cl,
                     "gamma_breakeven_here": gamma_here, "gamma_breakeven_cluster": gamma_cl})
    with open(os.path.join(a.data, "model.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(a.data, "model_inputs.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["quantity", "value"])
        for k, v in measured.items():
            w.writerow([k, f"{v:.6g}"])
        w.writerow(["cluster_latency_s (assumed)", CLUSTER_LATENCY_S])
        w.writerow(["cluster_bandwidth_Bps (assumed)", CLUSTER_BANDWIDTH_BPS])
        w.writerow(["gamma (assumed)", GAMMA])
    by = {r["ranks"]: r for r in rows}
    lines = ["| ranks | particles | max owned | max ghosts | bytes/step (max rank) | T per 10,000 steps, this "
             "machine's L, B (s) | same, cluster L, B (s) | paper's compute speed + cluster L, B (s) |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        lines.append(f"| {r['ranks']} | {r['particles']:,} | {r['owned_max']:.0f} | {r['ghosts_max']:.0f} | "
                     f"{r['bytes_step_max']:.0f} | {r['here_T10k_s']:.2f} | {r['cluster_T10k_s']:.2f} | "
                     f"{r['paperspeed_T10k_s']:.1f} |")
    growth = {k: by[1000][k] / by[27][k] - 1 for k in ("here_T10k_s", "cluster_T10k_s", "paperspeed_T10k_s")}
    lines.append("")
    lines.append("Growth 27 -> 1000 ranks: this machine's L, B {:+.1%}; cluster L, B {:+.1%}; paper's compute "
                 "speed with cluster L, B {:+.1%}; the paper measured {:+.1%}.".format(
                     growth["here_T10k_s"], growth["cluster_T10k_s"], growth["paperspeed_T10k_s"],
                     PAPER_POINTS[1000] / PAPER_POINTS[27] - 1))
    lines.append("")
    lines.append("Interactions across ranks computed once (reaction sent back) against twice (today), per "
                 "10,000 steps:")
    lines.append("")
    lines.append("| ranks | ghost fraction (max rank) | twice, this machine (s) | once, this machine (s) | twice, "
                 "cluster (s) | once, cluster (s) | once pays above gamma (this machine / cluster) |")
    lines.append("| --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        if r["ghosts_max"] == 0:
            continue
        lines.append(f"| {r['ranks']} | {r['ghosts_max'] / r['owned_max']:.2f} | {r['here_T10k_s']:.2f} | "
                     f"{r['here_once_T10k_s']:.2f} | {r['cluster_T10k_s']:.2f} | {r['cluster_once_T10k_s']:.2f} | "
                     f"{r['gamma_breakeven_here']:.2f} / {r['gamma_breakeven_cluster']:.2f} |")
    lines.append("")
    lines.append("Measured inputs: " + ", ".join(f"{k} = {v:.4g}" for k, v in measured.items()))
    md = "\n".join(lines) + "\n"
    with open(os.path.join(a.data, "model.md"), "w") as f:
        f.write(md)
    print(md)
    plot_model(a, rows)


def plot_model(a, rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    P = [r["ranks"] for r in rows]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.8))
    here = [r["here_T10k_s"] for r in rows]
    ax1.stackplot(P, [r["here_compute_s"] * PAPER_STEPS for r in rows],
                  [r["here_comm_s"] * PAPER_STEPS for r in rows], [r["here_reduce_s"] * PAPER_STEPS for r in rows],
                  labels=["compute (measured cost per particle-step)", "ghost exchange (L, B of this machine)",
                          "reductions (ceil(log2 P) x L)"], alpha=0.8)
    ax1.plot(P, [r["cluster_T10k_s"] for r in rows], "k--", label="total with the assumed cluster L, B")
    ax1.set_xscale("log")
    ax1.set_xlabel("compute ranks (one 15 mm subdomain each)")
    ax1.set_ylabel("projected seconds per 10,000 steps")
    ax1.set_title("Basalt: projected weak scaling (Table 2 partitions)")
    ax1.set_ylim(0, max(here) * 1.3)
    ax1.legend(loc="upper left", fontsize=8)
    base = {k: next(r[k] for r in rows if r["ranks"] == 27) for k in ("here_T10k_s", "cluster_T10k_s",
                                                                      "paperspeed_T10k_s")}
    ax2.plot(P, [r["here_T10k_s"] / base["here_T10k_s"] for r in rows], "o-", label="Basalt, this machine's L, B")
    ax2.plot(P, [r["cluster_T10k_s"] / base["cluster_T10k_s"] for r in rows], "s--",
             label="Basalt, assumed cluster L, B")
    ax2.plot(P, [r["paperspeed_T10k_s"] / base["paperspeed_T10k_s"] for r in rows], "^:",
             label="paper's compute speed, same model")
    ax2.plot(list(PAPER_POINTS), [PAPER_POINTS[k] / PAPER_POINTS[27] for k in PAPER_POINTS], "r*", ms=14,
             label="ESyS-Particle, paper (measured)")
    ax2.set_xscale("log")
    ax2.axhline(1.0, color="grey", lw=0.5)
    ax2.set_xlabel("compute ranks")
    ax2.set_ylabel("time relative to 27 ranks")
    ax2.set_title("Weak-scaling growth")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    os.makedirs(os.path.dirname(a.plot), exist_ok=True)
    fig.savefig(a.plot, dpi=110)
    print("wrote", a.plot)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("steps_to_run", nargs="*", default=["table", "pingpong", "runs", "model"],
                    choices=["table", "packed", "pingpong", "runs", "model", "weak"])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--data", default=os.path.join(ROOT, "docs", "data", "paper_study"))
    ap.add_argument("--plot", default=os.path.join(ROOT, "docs", "img", "weak_scaling.png"))
    ap.add_argument("--cube1", default=bt.reference_cube())
    ap.add_argument("--packed", default=os.path.join(ROOT, "out", "paper_study", "cube15_seed7.h5"))
    ap.add_argument("--max-n", type=int, default=10)
    ap.add_argument("--pack", type=int, default=4, help="step packed: pack the cubes n = 1 .. this")
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args()
    a.bin = lambda name: bt.binary(name, build=a.build)
    # hwloc's GL plugin (loaded by Open MPI) opens X display :0 when there is one; on this machine another job's
    # X server on :0 came and went, and processes died with "X connection to :0 broken" (failures.log).
    os.environ.setdefault("HWLOC_COMPONENTS", "-gl")
    os.makedirs(a.data, exist_ok=True)
    t0 = time.time()
    for s in a.steps_to_run:
        steps = {"table": step_table, "packed": step_packed, "pingpong": step_pingpong, "runs": step_runs,
                 "model": step_model, "weak": step_weak}
        steps[s](a)
    print(f"paper_study: done in {time.time() - t0:.0f} s")


if __name__ == "__main__":
    main()
