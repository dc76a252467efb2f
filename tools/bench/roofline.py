#!/usr/bin/python3
"""A roofline for every benchmark (issue 47): each phase's time per particle-step against the floors that
this machine's memory bandwidth and peak flops set for the bytes and flops the phase must move and compute.

    source scripts/mpi-env.sh
    /usr/bin/python3 tools/bench/roofline.py [--work out/roofline] [--repeats 3] [--bin build/bin]
        [--output docs/bench/roofline.md] [--plot docs/img/roofline.png] [--quick]

What it does:
  1. machine_limits (tools/bench/machine_limits.cpp, in --bin): copy/triad bandwidth at cache and memory sizes,
     gathers, peak FMA flops, on 1 and 2 threads;
  2. the benchmarks, each --repeats times at 1 rank (basalt-run's own per-phase timers, and its "forces by model
     kind" line; each phase's best over the repeats: the machine is shared):
       wave 15 mm   scenes/wave.toml on tests/data/cube1.geo (8,948 spheres), 2,000 steps
       wave 60 mm   the same cube tiled 4x4x4 (tools/bench/wave_tile_geo.py, 572,672 spheres), 300 steps
       granular     tools/bench/granular_bench.py's settled 20,840-sphere Hertz-Mindlin pile, 1,000 steps
       UCS          scenes/ucs-esys.toml (3,407 spheres, 10,739 rotational bonds), 4,000 steps
  3. the bytes and flops of each phase per particle-step from the data layout (cost_model below: the arrays
     each loop reads and writes, sizeof each element; the bonds, listed pairs, contacts and wall candidates
     per particle counted on the scene's geometry), and the floors: bytes / bandwidth (of the cache level the
     solver's arrays fit in, and of memory), flops / peak (double, widest vectors), neighbour gathers x the
     measured cost of a sorted gather;
  4. a markdown table (stdout and --output) and a roofline plot (--plot).
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tomllib

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)

ROOT = bt.ROOT

# ---------------------------------------------------------------------------------------------- the cost model
# Bytes and flops per particle-step, counted from the loops named beside each entry, in double (S = 8 bytes;
# float: S = 4). "Compulsory" bytes: every array a loop touches, read once per step (and written once when
# the loop writes it), as if each particle's gathered data stayed in cache between its neighbours' visits:
# the floor a perfectly streaming loop would meet. Index, history and per-bond arrays stream once per
# interaction. Flops count + - * / sqrt as one each (a sqrt or a division takes far longer than an FMA: the
# compute floor below is therefore optimistic). Counts marked "est." are rough (within ~30 %): the loops are
# long (rotational bonds, Hertz-Mindlin) or depend on run-time state (rebuilds).

# Per-particle arrays of each loop family (in units of S unless noted).
INTEGRATION = {
    # integrate/integrators.hpp kick_zero_drift: reads x y z v f inv_mass (10 S) and x0 y0 z0 (floats, 12 B),
    # writes x y z v and zeroes f (9 S); 24 flops (+7 with a deferred kick).
    "first": (19, 12, 24),
    # kick_energy / kick: reads v f inv_mass (7 S), writes v (3 S); 7 flops, +6 with the kinetic energy.
    "second": (10, 0, 13),
    # rotate_kick_zero_drift: w t (reads, w written, t zeroed: 12 S), inv_mass radius (2 S); 12 flops,
    # with orientations (q read and written, 8 S) ~45 more (a quaternion turn with a normalisation; est.).
    "rotate": (14, 0, 12),
    "orientation": (8, 0, 45),
}

# bond models: (bytes per particle in S, bytes per bond in S, bytes per bond fixed, flops per bond)
BONDS = {
    # interactions/bond_driver.hpp: per particle x y z read, f read+written (9 S); per bond ia ib (8 B), r0 (S);
    # 24 flops (distance 8, sqrt, force 3, f on both ends 12).
    "linear_bond": (9, 1, 8, 24),
    # interactions/rot_bond_driver.hpp + models/rot_bond.hpp: per particle x y z, initial x y z, q (10 S read),
    # f and torque read+written (12 S); per bond ia ib (8 B), r0 and the per-bond springs and strengths
    # (~9 S); ~250 flops (relative rotation from the quaternions, 4 springs, torques, ESyS's criterion; est.).
    "rot_bond": (22, 9, 8, 250),
}

# pair models: (bytes per particle in S, fixed bytes per particle, bytes per listed pair, flops per listed
# pair, flops per touching pair)
PAIRS = {
    # interactions/pair_driver.hpp loop_over: per particle x y z r read, f read+written (10 S), a row offset
    # (4 B); per listed pair the neighbour index (4 B); 11 flops per listed pair (distance, rsum, test), 16 per
    # touching pair (sqrt, force, both ends).
    "linear_elastic": (10, 4, 4, 11, 16),
    # pair_driver.hpp rows/batches + models/hertz_mindlin.hpp: per particle x y z r v w read (10 S), f t
    # read+written (12 S), offset (4 B); per listed pair the index (4 B) and the history (3 doubles, read and
    # written: 48 B); ~140 flops per touching pair (law ~75 with 3 sqrt, contact-point velocity ~30, force and
    # torques on both ends ~35; est.).
    "hertz_mindlin": (22, 4, 52, 11, 140),
    # models/friction.hpp (rot_friction): the same arrays; history 4 doubles (64 B read+written) and the
    # unbonded-entry index (4 B) per listed pair; ~90 flops per touching pair (est.).
    "rot_friction": (22, 4, 72, 11, 90),
}

# walls: (bytes per candidate in S, fixed bytes per candidate, flops per candidate)
WALLS = {
    # interactions/wall_driver.hpp, models/elastic_wall.hpp: candidate index (4 B), x y z r read, f read+written
    # (10 S); ~12 flops.
    "elastic": (10, 4, 12),
    # models/hertz_mindlin.hpp HertzMindlinWall: x y z r v w read, f t read+written (22 S), index and history
    # (4 + 48 B); ~120 flops (est.).
    "hertz_mindlin": (22, 52, 120),
}

# body forces per particle: (bytes in S, fixed bytes, flops)
BODIES = {
    "gravity": (7, 0, 3),  # models/gravity.hpp: inv_mass read, f read+written
    # models/damping.hpp damp_all: v read, f read+written, inv_mass (10 S), dissipated (8 B) and flag (1 B)
    # written; ESyS's iteration twice in registers: ~45 flops (est.).
    "linear_damping": (10, 9, 45),
    "rotational_damping": (11, 9, 50),  # w, torque, inv_mass, radius
}


def cost_model(scene, counts, S=8):
    """{phase: (bytes, flops, gathers, note)} per particle-step of `scene` (parsed TOML) with `counts`
    (scene_counts: per particle bonds, listed, loose, touching, wall_candidates, and rebuilds_per_step,
    array_bytes). gathers: the neighbour loads (one particle's data through an index) per particle-step."""
    n = counts
    rot = bool(scene.get("particles", {}).get("rotation", False))
    bond_types = [i["type"] for i in scene.get("interactions", []) if i["type"] in BONDS]
    pair_types = [i["type"] for i in scene.get("interactions", []) if i["type"] in PAIRS]
    unknown = [i["type"] for i in scene.get("interactions", []) if i["type"] not in BONDS and i["type"] not in PAIRS]
    if unknown:
        raise SystemExit(f"roofline: no cost model for {unknown} (add it to tools/bench/roofline.py)")
    out = {}
    # integration
    b, fixed, f = INTEGRATION["first"]
    byt, flo = b * S + fixed, f
    symplectic = scene.get("run", {}).get("integrator", "velocity_verlet") == "symplectic_euler"
    fields_every = min([fl.get("every", 1) for fl in scene.get("output", {}).get("fields", [])] or [0])
    if not symplectic:
        if fields_every == 1:  # the kick is made at once (a second pass) when a saver reads the velocities
            b2, _, f2 = INTEGRATION["second"]
            byt, flo = byt + b2 * S, flo + f2
        else:
            flo += 7  # deferred into the next step's pass
    orient = "rot_bond" in bond_types
    if rot:
        b3, _, f3 = INTEGRATION["rotate"]
        byt, flo = byt + b3 * S, flo + f3
        if orient:
            b4, _, f4 = INTEGRATION["orientation"]
            byt, flo = byt + b4 * S, flo + f4
    out["integration"] = (byt, flo, 0, "counted")
    # bonds
    if bond_types:
        bp, bb, bf, fl = BONDS[bond_types[0]]
        out["bonds"] = (bp * S + n["bonds"] * (bb * S + bf), n["bonds"] * fl, 2 * n["bonds"],
                        "counted" if bond_types[0] == "linear_bond" else "est.")
    # contacts
    if pair_types:
        pp, pfix, pl, fl_l, fl_t = PAIRS[pair_types[0]]
        listed = n["loose"]
        out["contacts"] = (pp * S + pfix + listed * pl, listed * fl_l + n["touching"] * fl_t, listed,
                           "counted" if pair_types[0] == "linear_elastic" else "est.")
    # walls
    walls = scene.get("walls", [])
    if walls:
        kind = "hertz_mindlin" if any(w.get("interaction") == "hertz_mindlin" for w in walls) else "elastic"
        wb, wfix, wf = WALLS[kind]
        c = n["wall_candidates"]
        out["walls"] = (c * (wb * S + wfix), c * wf, c, "counted" if kind == "elastic" else "est.")
    # body forces
    bodies = [bf["type"] for bf in scene.get("body_forces", []) if bf["type"] in BODIES]
    if bodies:
        byt = sum(BODIES[t][0] * S + BODIES[t][1] for t in bodies)
        out["body forces"] = (byt, sum(BODIES[t][2] for t in bodies), 0, "est.")
    # neighbour rebuilds, per step: every array reordered (read and written) and the lists written (4 B per
    # listed entry), ~3 candidate tests of 11 flops per listed pair (rough).
    rb = n["rebuilds_per_step"]
    out["neighbour search"] = (rb * (2 * n["array_bytes"] + 4 * n["listed"] + 16), rb * 33 * n["listed"], 0,
                               "est.")
    return out


# ---------------------------------------------------------------------------------------------- counts


def near_pairs(pos, cutoff):
    """(P, 2) index pairs i < j of the points `pos` (N, 3) closer than `cutoff`, each once: a cell grid of
    cutoff-wide cells, every point against the points of its cell and the 26 around it (numpy only)."""
    import numpy as np
    c = np.floor((pos - pos.min(axis=0)) / cutoff).astype(np.int64) + 1  # a margin of empty cells
    dims = c.max(axis=0) + 2
    key = (c[:, 0] * dims[1] + c[:, 1]) * dims[2] + c[:, 2]
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    found = [np.zeros((0, 2), np.int64)]
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dz in (-1, 0, 1):
                other = key + (dx * dims[1] + dy) * dims[2] + dz
                start = np.searchsorted(sorted_key, other, "left")
                count = np.searchsorted(sorted_key, other, "right") - start
                i = np.repeat(np.arange(len(pos)), count)
                first = np.repeat(start - (np.cumsum(count) - count), count)
                j = order[first + np.arange(count.sum())]
                keep = i < j
                i, j = i[keep], j[keep]
                near = ((pos[i] - pos[j]) ** 2).sum(axis=1) < cutoff * cutoff
                found.append(np.stack([i[near], j[near]], axis=1))
    return np.concatenate(found)


def scene_counts(pos, rad, bonds, ids, scene, skin):
    """Per particle: bonds, listed pairs (closer than ri + rj + skin; bonded pairs are not listed unless
    bonds can break, as the solver's lists do), loose (listed and not bonded: what the pair loop evaluates),
    touching (overlapping, not bonded), wall_candidates (particles within r + skin of a wall plane).
    pos: (N, 3) array, rad: (N,), bonds: (B, 2) ids, ids: (N,)."""
    import numpy as np
    N = len(rad)
    pairs = near_pairs(pos, 2 * float(rad.max()) + skin)
    d = np.linalg.norm(pos[pairs[:, 0]] - pos[pairs[:, 1]], axis=1)
    rs = rad[pairs[:, 0]] + rad[pairs[:, 1]]
    near = pairs[d < rs + skin]
    touch = pairs[d < rs]
    index = {int(v): k for k, v in enumerate(ids)}
    bonded = set()
    for a, b in bonds:
        i, j = index[int(a)], index[int(b)]
        bonded.add((min(i, j), max(i, j)))

    def unbonded(pp):
        return sum(1 for i, j in pp if (min(i, j), max(i, j)) not in bonded)

    loose = unbonded(near) if bonded else len(near)
    breakable = any(i["type"] == "rot_bond" or "break_strain" in i for i in scene.get("interactions", []))
    listed = len(near) if breakable else loose
    cand = 0
    for w in scene.get("walls", []):
        p0, nrm = np.array(w["point"], float), np.array(w["normal"], float)
        nrm = nrm / np.linalg.norm(nrm)
        cand += int(((pos - p0) @ nrm - rad < skin).sum())
    return {"particles": N, "bonds": len(bonds) / N, "listed": listed / N, "loose": loose / N,
            "touching": unbonded(touch) / N, "wall_candidates": cand / N}


# ---------------------------------------------------------------------------------------------- floors


def level_bandwidth(limits, array_bytes_total, threads=1):
    """(GB/s, level name) of the triad at the smallest measured size whose three arrays hold at least the
    solver's arrays (array_bytes_total), else memory's."""
    rows = sorted((r for r in limits["stream"] if r["threads"] == threads), key=lambda r: r["mb"])
    for r in rows:
        if 3 * r["mb"] * 1e6 >= array_bytes_total:
            return r["triad_gbs"], f"{3 * r['mb']:g} MB triad"
    r = rows[-1]
    return r["triad_gbs"], f"{3 * r['mb']:g} MB triad"


def memory_bandwidth(limits, threads=1):
    rows = [r for r in limits["stream"] if r["threads"] == threads]
    return max(rows, key=lambda r: r["mb"])["triad_gbs"]


def peak(limits, threads=1, key="double_vector_gflops"):
    return next(r[key] for r in limits["fma"] if r["threads"] == threads)


def sorted_gather_ns(limits, threads=1):
    rows = [r for r in limits["gather"] if r["threads"] == threads]
    return min(rows, key=lambda r: r["mb"])["sorted_ns"]


def floors(cost, bw_gbs, mem_gbs, peak_gflops, gather_ns):
    """ns per particle-step: (bandwidth floor at the arrays' level, memory floor, compute floor, gather
    floor) of (bytes, flops, gathers)."""
    byt, flo, gat = cost[0], cost[1], cost[2]
    return byt / bw_gbs, byt / mem_gbs, flo / peak_gflops, gat * gather_ns


# ---------------------------------------------------------------------------------------------- running


def run_basalt(exe, scene, args, out, cwd=None):
    cmd = [exe, scene, "--output", out] + [str(a) for a in args]
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd, env=bt.mpi_env((), ranks=1, eager=True))
    if p.returncode != 0:
        raise SystemExit(f"roofline: failed: {' '.join(cmd)}\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    r = bt.parse_run(p.stdout)
    if "phases" not in r or "force_kinds" not in r:
        raise SystemExit(f"roofline: no phase lines in the output of {' '.join(cmd)} (an older basalt-run?)")
    return r


def best_phases(runs):
    """Each phase's (and force kind's) smallest ms per step over the runs, and the run of the smallest loop."""
    best = min(runs, key=lambda r: r["loop_s"])
    ph = {k: min(r["phases"][k][0] for r in runs) for k in best["phases"]}
    kinds = {k: min(r["force_kinds"][k] for r in runs) for k in best["force_kinds"]}
    return best, ph, kinds


def read_geometry(path):
    """(ids, pos, rad, bonds) of a .geo or .h5 geometry, numpy arrays."""
    import numpy as np
    if path.endswith(".geo"):
        _, _, parts, bonds = bt.read_geo(path)
        ids = np.array([p[0] for p in parts])
        pos = np.array([p[1:4] for p in parts], float)
        rad = np.array([p[4] for p in parts], float)
        return ids, pos, rad, np.array([(a, b) for a, b, _ in bonds]).reshape(-1, 2)
    ids, pos, rad, bonds = bt.read_h5(path, "particles/id", "particles/position", "particles/radius", "bonds/pairs")
    if bonds is None:
        bonds = np.zeros((0, 2), int)
    return np.asarray(ids), np.asarray(pos, float), np.asarray(rad, float), np.asarray(bonds).reshape(-1, 2)


def benchmarks(a, work):
    """[(name, scene path, geometry path, args, cwd)] of the benchmarks, making their inputs in `work`."""
    cube1 = bt.reference_cube()
    wave = bt.repo_path("scenes", "wave.toml")
    out = [("wave 15 mm", wave, cube1, ["--geometry", cube1, "--steps", a.steps_wave], None)]
    if not a.quick:
        cube60 = os.path.join(work, "cube60-tiled.geo")
        if not os.path.exists(cube60):
            subprocess.run(["/usr/bin/python3", bt.repo_path("tools", "bench", "wave_tile_geo.py"), cube1, "4", cube60],
                           check=True, stdout=subprocess.DEVNULL)
        out.append(("wave 60 mm", wave, cube60, ["--geometry", cube60, "--steps", a.steps_wave60], None))
        gw = os.path.join(work, "granular")
        if not os.path.exists(os.path.join(gw, "bench.toml")):
            subprocess.run(["/usr/bin/python3", bt.repo_path("tools", "bench", "granular_bench.py"), "--work", gw,
                            "--bin", a.bin, "--codes", "basalt", "--ranks", "1", "--repeats", "1", "--steps", "100"],
                           check=True, stdout=subprocess.DEVNULL, env=bt.mpi_env())
        out.append(("granular 20 k", os.path.join(gw, "bench.toml"), os.path.join(gw, "settled.h5"),
                    ["--steps", a.steps_granular], gw))
    ucs = bt.repo_path("scenes", "ucs-esys.toml")
    out.append(("UCS", ucs, bt.repo_path("docs", "data", "esys-ucs", "box.geo"), ["--steps", a.steps_ucs], None))
    return out


def fmt_ns(v):
    return f"{v:.1f}" if v >= 10 else f"{v:.2f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--work", default="out/roofline")
    ap.add_argument("--bin", default=bt.bin_dir())
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--steps-wave", type=int, default=2000)
    ap.add_argument("--steps-wave60", type=int, default=300)
    ap.add_argument("--steps-granular", type=int, default=1000)
    ap.add_argument("--steps-ucs", type=int, default=4000)
    ap.add_argument("--quick", action="store_true", help="only the 15 mm wave and the UCS (no packing or settling)")
    ap.add_argument("--limits", default="", help="machine_limits' JSON from an earlier run (skip measuring)")
    ap.add_argument("--output", default="", help="also write the markdown report here")
    ap.add_argument("--plot", default="", help="the roofline plot (PNG)")
    ap.add_argument("--label", default="", help="a name for this build in the report (e.g. 'scalar build')")
    a = ap.parse_args()
    a.work = os.path.abspath(a.work)  # the benchmarks run in other folders
    os.makedirs(a.work, exist_ok=True)
    if a.limits:
        limits = json.load(open(a.limits))
    else:
        p = subprocess.run([bt.binary("machine_limits", a.bin), "--repeats", "10"], capture_output=True, text=True,
                           check=True)
        limits = json.loads(p.stdout)
        with open(os.path.join(a.work, "limits.json"), "w") as f:
            f.write(p.stdout)
    rows = []
    for name, scene_path, geo, args, cwd in benchmarks(a, a.work):
        runs = [run_basalt(bt.binary("basalt-run", a.bin), scene_path, args,
                           os.path.join(a.work, "out-" + name.replace(" ", "-")), cwd) for _ in range(a.repeats)]
        best, ph, kinds = best_phases(runs)
        scene = tomllib.load(open(scene_path, "rb"))
        ids, pos, rad, bonds = read_geometry(geo)
        counts = scene_counts(pos, rad, bonds, ids, scene, float(scene["run"].get("skin", 0)))
        counts["rebuilds_per_step"] = best["rebuilds"] / best["loop_steps"]
        counts["array_bytes"] = best["bytes_per_particle"]
        cost = cost_model(scene, counts)
        measured = {"integration": ph["integration"], "neighbour search": ph["neighbour search"],
                    "bonds": kinds.get("bond", 0), "contacts": kinds.get("pair", 0), "walls": kinds.get("wall", 0),
                    "body forces": kinds.get("body force", 0)}
        n = best["particles"]
        bw, level = level_bandwidth(limits, best["arrays_mb"] * 1e6)
        mem, pk, gns = memory_bandwidth(limits), peak(limits), sorted_gather_ns(limits)
        rows.append({"name": name, "particles": n, "counts": counts, "level": level, "bw": bw,
                     "loop_ns": best["loop_s"] / best["loop_steps"] / n * 1e9, "phases": {}})
        for phase, c in cost.items():
            t = measured[phase] * 1e6 / n  # ms per step -> ns per particle-step
            fb, fm, fc, fg = floors(c, bw, mem, pk, gns)
            rows[-1]["phases"][phase] = {"ns": t, "bytes": c[0], "flops": c[1], "gathers": c[2], "note": c[3],
                                         "floor_bw": fb, "floor_mem": fm, "floor_flops": fc, "floor_gather": fg}
        other = sum(v for k, v in ph.items() if k not in ("integration", "neighbour search")) * 1e6 / n - sum(
            measured[k] for k in ("bonds", "contacts", "walls", "body forces")) * 1e6 / n
        rows[-1]["unmodelled_ns"] = other
        print(f"{name}: {n} particles, {rows[-1]['loop_ns']:.1f} ns per particle-step", flush=True)
    report = render(rows, limits, a)
    print(report)
    if a.output:
        with open(a.output, "w") as f:
            f.write(report)
    with open(os.path.join(a.work, "roofline.json"), "w") as f:
        json.dump({"limits": limits, "rows": rows}, f, indent=1)
    if a.plot:
        plot(rows, limits, a.plot)


def cpu_name():
    try:
        return next(l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name"))
    except (OSError, StopIteration):
        return "?"


def vector_flags():
    try:
        flags = next(l.split(":", 1)[1].split() for l in open("/proc/cpuinfo") if l.startswith("flags"))
    except (OSError, StopIteration):
        return "?"
    names = [f for f in ("sse4_2", "avx", "avx2", "fma", "avx512f", "avx512vl", "avx512_bf16") if f in flags]
    return " ".join(names)


def render(rows, limits, a):
    import datetime
    L = lambda key, th=1: next(r for r in limits[key] if r["threads"] == th)  # noqa: E731
    mem1, mem2 = memory_bandwidth(limits, 1), memory_bandwidth(limits, 2)
    lines = [f"Roofline{' (' + a.label + ')' if a.label else ''}, {datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC, "
             f"{os.cpu_count()} cores ({cpu_name()}; vector extensions: {vector_flags()}; the build's widest vectors "
             f"{limits['vector']}), load {os.getloadavg()[0]:.1f} at the end; {a.repeats} repeats per benchmark at 1 rank, "
             "each phase's best.", "",
             "Machine (machine_limits, best of 10 passes): "
             + "; ".join(f"triad {r['mb'] * 3:g} MB {r['triad_gbs']:.1f} GB/s" for r in limits["stream"]
                         if r["threads"] == 1)
             + f"; memory triad on 2 threads {mem2:.1f} GB/s ({mem2 / mem1:.2f}x one)"
             + f"; sorted gather {L('gather')['sorted_ns']:.2f} ns, random {L('gather')['random_ns']:.2f} ns per index "
               f"({L('gather')['mb']:g} MB), random in memory "
               f"{max((r for r in limits['gather'] if r['threads'] == 1), key=lambda r: r['mb'])['random_ns']:.2f} ns"
             + f"; peak double {L('fma')['double_scalar_gflops']:.1f} GFLOP/s scalar, "
               f"{L('fma')['double_vector_gflops']:.1f} vector; float {L('fma')['float_vector_gflops']:.1f} vector.", "",
             "| benchmark | phase | ns per particle-step | bytes | flops | gathers | bandwidth floor (arrays' level) "
             "| memory floor | compute floor | gather floor | limit reached | counts |",
             "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |"]
    for r in rows:
        for phase, v in r["phases"].items():
            lim, which = max((v["floor_bw"], "bandwidth"), (v["floor_flops"], "compute"), (v["floor_gather"], "gathers"))
            frac = f"{100 * lim / v['ns']:.0f} % ({which})" if v["ns"] > 0 else "-"
            lines.append(f"| {r['name']} | {phase} | {fmt_ns(v['ns'])} | {v['bytes']:.0f} | {v['flops']:.0f} | "
                         f"{v['gathers']:.1f} | {fmt_ns(v['floor_bw'])} | {fmt_ns(v['floor_mem'])} | "
                         f"{fmt_ns(v['floor_flops'])} | {fmt_ns(v['floor_gather'])} | {frac} | {v['note']} |")
        tot = {k: sum(v[k] for v in r["phases"].values()) for k in ("ns", "floor_bw", "floor_mem", "floor_flops",
                                                                    "floor_gather")}
        lim = max(tot["floor_bw"], tot["floor_flops"], tot["floor_gather"])  # the largest of the step's floors
        lines.append(f"| {r['name']} | **step** ({r['loop_ns']:.1f} ns measured, {r['unmodelled_ns']:.1f} in "
                     f"forces' bookkeeping; arrays at {r['level']}, {r['bw']:.0f} GB/s) | {fmt_ns(tot['ns'])} | | | | "
                     f"{fmt_ns(tot['floor_bw'])} | {fmt_ns(tot['floor_mem'])} | {fmt_ns(tot['floor_flops'])} | "
                     f"{fmt_ns(tot['floor_gather'])} | **{100 * lim / max(r['loop_ns'], 1e-9):.0f} %** | |")
    lines += ["", "Per particle (from the geometry): "
              + "; ".join(f"{r['name']}: {r['counts']['bonds']:.2f} bonds, {r['counts']['listed']:.2f} listed pairs "
                          f"({r['counts']['loose']:.2f} evaluated), {r['counts']['touching']:.2f} touching, "
                          f"{r['counts']['wall_candidates']:.3f} wall candidates, "
                          f"{r['counts']['rebuilds_per_step'] * 1000:.1f} rebuilds per 1,000 steps"
                          for r in rows) + "."]
    return "\n".join(lines) + "\n"


def plot(rows, limits, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8.5, 5.5))
    ai = [10 ** (k / 20) for k in range(-60, 41)]
    pk = peak(limits)
    pks = peak(limits, key="double_scalar_gflops")
    for r in sorted((r for r in limits["stream"] if r["threads"] == 1), key=lambda r: r["mb"]):
        ax.plot(ai, [min(pk, x * r["triad_gbs"]) for x in ai], lw=1,
                label=f"triad {3 * r['mb']:g} MB: {r['triad_gbs']:.0f} GB/s")
    ax.axhline(pks, color="grey", ls=":", lw=1, label=f"scalar double peak {pks:.1f} GFLOP/s")
    markers = "osD^v<>"
    for k, r in enumerate(rows):
        for phase, v in r["phases"].items():
            if v["bytes"] <= 0 or v["ns"] <= 0 or v["flops"] <= 0:
                continue
            x, y = v["flops"] / v["bytes"], v["flops"] / v["ns"]
            ax.plot([x], [y], markers[k % len(markers)], color=f"C{k}", ms=6)
            ax.annotate(phase, (x, y), fontsize=7, xytext=(3, 3), textcoords="offset points")
        ax.plot([], [], markers[k % len(markers)], color=f"C{k}", label=r["name"])
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("arithmetic intensity (flops per byte, counted)")
    ax.set_ylabel("GFLOP/s reached (counted flops / measured time)")
    ax.set_title(f"Basalt roofline, 1 rank, double ({limits['vector']} build; {cpu_name()})")
    ax.legend(fontsize=7, loc="lower right")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
