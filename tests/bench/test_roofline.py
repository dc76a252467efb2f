#!/usr/bin/python3
"""Unit test of the roofline tool (tools/bench/roofline.py, docs/BENCHMARKS.md "Roofline").

    /usr/bin/python3 tests/bench/test_roofline.py [MACHINE_LIMITS]

Checks the counts (bonds, listed pairs, contacts, wall candidates) of a 4-sphere scene against a hand count,
the bytes and flops per particle-step of the wave scene's phases against the hand count from the loops'
arrays, the floors' arithmetic and the choice of the cache level; with MACHINE_LIMITS (ctest passes the built
program), runs it on tiny arrays and checks that every figure is positive and finite. Plain asserts; prints
"N passed, 0 failed" and exits 0, or names the failed check and exits 1.
"""
import json
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools", "bench"))
import roofline as rl  # noqa: E402
from script_tests import run_tests  # noqa: E402  (tests/bench/script_tests.py)

# The wave scene's shape (scenes/wave.toml): linear bonds, linear elastic contacts, one elastic wall at z = 0,
# velocity Verlet, the kinetic energy saved every step.
WAVE = {"run": {"skin": 0.1, "integrator": "velocity_verlet"},
        "interactions": [{"type": "linear_bond", "K": 1.0}, {"type": "linear_elastic", "K": 1.0}],
        "walls": [{"point": [0, 0, 0], "normal": [0, 0, 1]}],
        "output": {"fields": [{"type": "kinetic_energy", "every": 1}]}}


def four_spheres():
    """Four spheres of radius 0.5 on a line at height 0.55 (0.05 above the wall: all within the skin of it):
    0-1 bonded (distance 1.0), 1-2 listed but apart (1.05 < 1.0 + skin), 2-3 touching (0.95)."""
    import numpy as np
    pos = np.array([[0, 0, 0.55], [1.0, 0, 0.55], [2.05, 0, 0.55], [3.0, 0, 0.55]])
    rad = np.full(4, 0.5)
    ids = np.array([10, 11, 12, 13])
    bonds = np.array([[10, 11]])
    return pos, rad, bonds, ids


def test_counts():
    pos, rad, bonds, ids = four_spheres()
    c = rl.scene_counts(pos, rad, bonds, ids, WAVE, 0.1)
    assert c["particles"] == 4 and c["bonds"] == 0.25, c
    # bonds cannot break: the bonded pair is not listed; 1-2 and 2-3 are
    assert c["listed"] == 0.5 and c["loose"] == 0.5 and c["touching"] == 0.25, c
    assert c["wall_candidates"] == 1.0, c
    # breakable bonds: the bonded pair is listed (and marked), the pair loop evaluates the other two
    breakable = dict(WAVE, interactions=[{"type": "linear_bond", "K": 1.0, "break_strain": 0.1},
                                         {"type": "linear_elastic", "K": 1.0}])
    c = rl.scene_counts(pos, rad, bonds, ids, breakable, 0.1)
    assert c["listed"] == 0.75 and c["loose"] == 0.5, c


def test_wave_costs():
    counts = {"bonds": 0.25, "listed": 0.5, "loose": 0.5, "touching": 0.25, "wall_candidates": 1.0,
              "rebuilds_per_step": 0.01, "array_bytes": 238}
    m = rl.cost_model(WAVE, counts)
    # Hand count, double (8 B):
    # integration: kick_zero_drift reads x y z v f inv_mass (80 B) and the float x0 y0 z0 (12 B), writes x y z v f
    # (72 B); the kinetic-energy kick reads v f inv_mass (56 B) and writes v (24 B): 244 B; 24 + 13 flops.
    assert m["integration"][:3] == (244, 37, 0), m["integration"]
    # bonds: x y z read, f read and written (72 B); a quarter bond each: ia ib r0 (16 B) -> 4 B; 24 flops -> 6;
    # two gathers per bond -> 0.5.
    assert m["bonds"][:3] == (76, 6, 0.5), m["bonds"]
    # contacts: x y z r read, f read and written (80 B), the row offset (4 B), half a listed entry (4 B) -> 2 B;
    # 11 flops per listed pair and 16 more per touching pair: 5.5 + 4.
    assert m["contacts"][:3] == (86, 9.5, 0.5), m["contacts"]
    # walls: every particle a candidate: index (4 B), x y z r read, f read and written (80 B); 12 flops.
    assert m["walls"][:3] == (84, 12, 1.0), m["walls"]
    # neighbour search, once per 100 steps: all 238 B of arrays read and written, 4 B per listed entry, 16 B of
    # cells; 33 flops per listed pair.
    nb = m["neighbour search"]
    assert math.isclose(nb[0], 0.01 * (2 * 238 + 2 + 16)) and math.isclose(nb[1], 0.01 * 33 * 0.5), nb
    assert "body forces" not in m and "counted" == m["bonds"][3] == m["contacts"][3], m


def test_rotation_and_unknown_models():
    counts = {"bonds": 0, "listed": 4, "loose": 4, "touching": 2, "wall_candidates": 0, "rebuilds_per_step": 0,
              "array_bytes": 300}
    gran = {"particles": {"rotation": True}, "run": {"skin": 0.1},
            "interactions": [{"type": "hertz_mindlin"}], "body_forces": [{"type": "gravity"}],
            "output": {"fields": [{"type": "kinetic_energy", "every": 500}]}}
    m = rl.cost_model(gran, counts)
    # deferred kick: no second pass (+7 flops); rotation: 14 S more, 12 flops
    assert m["integration"][:2] == (164 + 112, 24 + 7 + 12), m["integration"]
    assert m["contacts"][:2] == (22 * 8 + 4 + 4 * 52, 4 * 11 + 2 * 140), m["contacts"]
    assert m["body forces"][:2] == (56, 3), m["body forces"]
    try:
        rl.cost_model({"interactions": [{"type": "jkr"}]}, counts)
    except SystemExit as e:
        assert "jkr" in str(e), e
    else:
        raise AssertionError("a model without a cost model was accepted")


def test_floors_and_levels():
    # 100 B at 50 GB/s = 2 ns; at 10 GB/s 10 ns; 200 flops at 100 GFLOP/s = 2 ns; 4 gathers of 0.5 ns
    assert rl.floors((100, 200, 4), 50, 10, 100, 0.5) == (2.0, 10.0, 2.0, 2.0)
    limits = {"stream": [{"threads": 1, "mb": 0.25, "triad_gbs": 150.0}, {"threads": 1, "mb": 4, "triad_gbs": 90.0},
                         {"threads": 1, "mb": 256, "triad_gbs": 14.0}, {"threads": 2, "mb": 256, "triad_gbs": 20.0}]}
    assert rl.level_bandwidth(limits, 0.5e6)[0] == 150.0  # fits three 0.25 MB arrays
    assert rl.level_bandwidth(limits, 2.1e6)[0] == 90.0  # the 15 mm cube's 2.1 MB: the 12 MB level
    assert rl.level_bandwidth(limits, 2e9)[0] == 14.0  # beyond every size: memory
    assert rl.memory_bandwidth(limits, 2) == 20.0


def machine_limits(exe):
    """The bandwidth program on tiny arrays: sane, positive output."""
    p = subprocess.run([exe, "--sizes", "0.008", "0.1", "--gather-mb", "0.2", "--gather-cache-mb", "0.05",
                        "--threads", "1", "2", "--repeats", "2", "--fma-iters", "20000"],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    r = json.loads(p.stdout)
    assert r["vector"] in ("SSE2", "AVX", "AVX-512") and r["vector_bytes"] in (16, 32, 64), r
    assert len(r["stream"]) == 4 and len(r["gather"]) == 4 and len(r["fma"]) == 2, r
    for row in r["stream"] + r["gather"] + r["fma"]:
        for k, v in row.items():
            assert isinstance(v, (int, float)) and math.isfinite(v) and v > 0, (k, row)
    assert {row["threads"] for row in r["stream"]} == {1, 2}, r["stream"]


def test_near_pairs_equal_all_pairs():
    """The cell-grid pair search against every pair, on random points (some exactly a cell apart)."""
    import numpy as np
    rng = np.random.default_rng(7)
    pos = np.vstack([rng.random((300, 3)) * [6.0, 3.0, 4.0], [[0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]]])
    for cutoff in (0.4, 1.0, 2.5):
        got = rl.near_pairs(pos, cutoff)
        d2 = ((pos[:, None, :] - pos[None, :, :]) ** 2).sum(axis=2)
        i, j = np.nonzero(np.triu(d2 < cutoff * cutoff, k=1))
        want = set(zip(i.tolist(), j.tolist()))
        assert len(got) == len(want) and set(map(tuple, got.tolist())) == want, (cutoff, len(got), len(want))


def main():
    return run_tests(globals(), [("machine_limits", lambda: machine_limits(sys.argv[1]))] if len(sys.argv) > 1 else [])


if __name__ == "__main__":
    sys.exit(main())
