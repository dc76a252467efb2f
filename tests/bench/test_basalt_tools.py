#!/usr/bin/python3
"""Unit test of tools/basalt_tools.py, the module the Python scripts of tools/ share (docs/ARCHITECTURE.md).

    /usr/bin/python3 tests/bench/test_basalt_tools.py [BASALT_RUN]

Checks the parsers on recorded output (tests/bench/samples/: basalt-run's standard output at 1 rank and
at 2 compute ranks + 1 I/O rank, a fields.csv, /usr/bin/time -v's report of a basalt-run), the readers on
cube1.geo and on files it writes, and the places and MPI settings. With BASALT_RUN (ctest passes the
built basalt-run), also runs it for 20 steps on cube1.geo and parses that: a change of basalt-run's
summary lines that the parser no longer reads fails here. Plain asserts (no pytest); prints
"N passed, 0 failed" and exits 0, or names the failed check and exits 1.
"""
import math
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import basalt_tools as bt  # noqa: E402
from script_tests import run_tests  # noqa: E402  (tests/bench/script_tests.py)

SAMPLES = os.path.join(HERE, "samples")
CUBE = os.path.join(ROOT, "tests", "data", "cube1.geo")
PHASES = ["forces", "neighbour search", "communication", "integration", "output"]


def sample(name):
    with open(os.path.join(SAMPLES, name)) as f:
        return f.read()


def close(a, b, rel=1e-12):
    return abs(a - b) <= rel * max(abs(a), abs(b))


def test_parse_run_one_rank():
    r = bt.parse_run(sample("basalt-run-np1.txt"))
    assert r["particles"] == 8948 and r["bonds"] == 30090, r
    assert r["compute_ranks"] == 1 and r["io_ranks"] == 0 and r["dims"] == (1, 1, 1), r
    assert r["steps"] == 100 and r["dt"] == 0.001 and r["time_unit"] == "ms" and r["precision"] == "double", r
    assert r["critical_step"] == 0.005937, r["critical_step"]
    assert r["field_bytes"] == 112, r.get("field_bytes")
    # done: 100 steps in T s (S steps/s, M M particle-steps/s); start-up U s; R rebuilds
    assert r["loop_steps"] == 100, r
    assert r["loop_s"] == 0.034 and r["steps_per_s"] == 2978.8 and r["startup_s"] == 0.214, r
    assert close(r["particle_steps_per_s"], 26.654e6), r
    assert r["rebuilds"] == 1, r
    assert r["cpu_s"] == 0.019 and r["cpu_percent"] == 57, r
    assert list(r["phases"]) == PHASES, r["phases"]
    assert r["phases"]["forces"] == (0.2059, 61.3) and r["phases"]["output"] == (0.0004, 0.1), r["phases"]
    assert r["time_per_step"].startswith("forces "), r["time_per_step"]
    assert r["force_kinds"] == {"bond": 0.15, "pair": 0.04, "wall": 0.01, "body force": 0.0}, r["force_kinds"]
    assert r["arrays_mb"] == 2.1 and r["bytes_per_particle"] == 238, r
    assert set(r["output"]) == {"checkpoints", "frames", "fields"}, r["output"]
    assert r["output"]["fields"] == (1, 0.0, 0.0) and r["output"]["checkpoints"][0] == 0, r["output"]
    assert r["compute_wait_s"] == 0.0001 and "io_cpu_s" not in r, r
    assert "balance_start" not in r and "drawn" not in r, r


def test_parse_run_io_rank():
    r = bt.parse_run(sample("basalt-run-np2-io1.txt"))
    assert r["compute_ranks"] == 2 and r["io_ranks"] == 1 and r["dims"] == (2, 1, 1) and r["field_bytes"] == 136, r
    assert r["loop_steps"] == 100 and r["loop_s"] == 0.098 and close(r["particle_steps_per_s"], 9.116e6), r
    assert list(r["phases"]) == PHASES, r["phases"]  # the maxima, not the "by rank" line after it
    assert r["phases"]["communication"] == (0.5803, 59.1), r["phases"]
    assert r["balance_start"] == 1.002 and r["balance_end"] == 1.002 and r["rebalances"] == 0, r
    assert r["output"]["checkpoints"] == (1, 2.07, 0.066), r["output"]
    assert r["compute_wait_s"] == 0.063 and r["io_cpu_s"] == 0.048 and r["io_wall_s"] == 0.348, r


def test_parse_run_partial():
    # a failed run: the header and no summary
    r = bt.parse_run(sample("basalt-run-np1.txt").split("\ndone:")[0])
    assert r["particles"] == 8948 and "loop_s" not in r and "phases" not in r, r
    assert bt.parse_run("") == {}
    # a picture line as solver/app/basalt_run.cpp prints it
    r = bt.parse_run("  pictures         3 files      0.42 MB  draw     1.500 s (0.500 s per picture, longest 0.700 s); "
                     "3 of 4 drawn, 1 skipped\n  compute ranks waited 0.0100 s for output; I/O rank CPU time 2.000 s "
                     "over 3.000 s wall (66.7 %)\n")
    assert (r["pictures_files"], r["per_picture_s"], r["longest_s"], r["drawn"], r["due"], r["skipped"]) == \
        (3, 0.5, 0.7, 3, 4, 1), r
    assert r["io_cpu_s"] == 2.0 and r["io_wall_s"] == 3.0, r


def test_time_v():
    t = bt.parse_time_v(sample("time-v-basalt-run.txt"))
    assert t["max_rss_kb"] == 42032 and t["user_s"] == 0.17 and t["sys_s"] == 0.11, t
    assert close(t["wall_s"], 1.02), t
    assert t["exit_status"] == 0, t
    assert bt.parse_time_v("") == {}
    # h:mm:ss, and the largest of several reports (one per process)
    t = bt.parse_time_v("\tElapsed (wall clock) time (h:mm:ss or m:ss): 1:02:03\n"
                        "\tMaximum resident set size (kbytes): 10\n\tMaximum resident set size (kbytes): 30\n")
    assert t["wall_s"] == 3723 and t["max_rss_kb"] == 30, t


def test_read_fields():
    c = bt.read_fields(os.path.join(SAMPLES, "fields.csv"))
    assert list(c)[:3] == ["step", "time", "kinetic_energy"], list(c)
    assert c["step"] == list(range(1, 101)), c["step"]  # one row per step, after it
    assert all(type(x) is int for x in c["step"]) and type(c["time"][0]) is float, c["step"][:3]
    assert all(len(v) == 100 for v in c.values()), {k: len(v) for k, v in c.items()}
    assert c["time"][-1] == 0.1 and c["kinetic_energy"][-1] == 0.24022454479420208, c["kinetic_energy"][-1]
    with tempfile.TemporaryDirectory() as d:
        with open(os.path.join(d, "fields.csv"), "w") as f:
            f.write("step,time,kinetic_energy,bond_count\n0,0,1.5,10\n5,0.5,,nan\n10,1.0,2.5\n")
        c = bt.read_fields(d)  # a run folder
        assert c["step"] == [0, 5, 10] and c["kinetic_energy"][0] == 1.5, c
        assert math.isnan(c["kinetic_energy"][1]) and math.isnan(c["bond_count"][1]), c
        assert math.isnan(c["bond_count"][2]), c  # a short row


def test_read_geo():
    lo, hi, parts, bonds = bt.read_geo(CUBE)
    assert lo == [0, 0, 0] and hi == [15, 15, 15], (lo, hi)
    assert len(parts) == 8948 and len(bonds) == 30090, (len(parts), len(bonds))
    assert parts[0][0] == 0 and parts[0][5] == 1 and parts[0][4] == 0.4529056675, parts[0]
    assert bt.geo_particle_count(CUBE) == 8948
    with tempfile.TemporaryDirectory() as d:
        bad = os.path.join(d, "bad.geo")
        with open(bad, "w") as f:
            f.write("LSMGeometry 1.2\nBeginParticles\nSimple\n2\n0 0 0 0.5 0 1\n1 1 x 0.5 1 1\nEndParticles\n")
        try:
            bt.read_geo(bad)
            raise AssertionError("no GeoError")
        except bt.GeoError as e:
            assert f"{bad}:6:" in str(e), e


def test_read_h5():
    import h5py
    import numpy as np
    with tempfile.TemporaryDirectory() as d:
        for step in (100, 20):
            with h5py.File(os.path.join(d, f"ckpt_{step:06d}.h5"), "w") as f:
                f["particles/id"] = np.array([3, 1, 2]) + step
                f["particles/position"] = np.zeros((3, 3))
        last = bt.last_checkpoint(d)
        assert os.path.basename(last) == "ckpt_000100.h5", last
        ids, pos, missing = bt.read_h5(last, "particles/id", "particles/position", "bonds/pairs")
        assert list(ids) == [103, 101, 102] and pos.shape == (3, 3) and missing is None, (ids, pos, missing)
        assert bt.last_checkpoint(os.path.join(d, "none")) is None


def test_read_esys_checkpoint():
    with tempfile.TemporaryDirectory() as d:
        for w, ids in ((1, (0, 7)), (2, (14,))):
            with open(os.path.join(d, f"cp_t=3_{w}.txt"), "w") as f:
                f.write(f"{len(ids)}\n")
                for i in ids:
                    f.write(" ".join(str(float(i if k == 4 else k)) for k in range(29)) + "\n")
                f.write("\nBonded\n2\n0 7 0\n7 14 0\n")
        rows, bonds = bt.read_esys_checkpoint(os.path.join(d, "cp"), 3, workers=2)
        assert sorted(rows) == [0, 7, 14] and rows[7][4] == 7.0 and rows[7][13:16] == [13.0, 14.0, 15.0], rows
        assert bonds == 4, bonds
        rows, _ = bt.read_esys_checkpoint(os.path.join(d, "cp"), 3)
        assert sorted(rows) == [0, 7], rows


def test_places():
    assert bt.ROOT == ROOT, bt.ROOT
    assert bt.bin_dir() == os.path.join(ROOT, "build", "bin")
    assert bt.bin_dir(build="B") == os.path.join("B", "bin") and bt.bin_dir("X", "B") == "X"
    assert bt.binary("basalt-run", build="B") == os.path.join("B", "bin", "basalt-run")
    saved = os.environ.pop("BASALT_REFERENCE_DIR", None)
    try:
        assert bt.reference_cube() == CUBE, bt.reference_cube()
        os.environ["BASALT_REFERENCE_DIR"] = "/elsewhere"
        assert bt.reference_cube() == os.path.join("/elsewhere", "cube1.geo")
    finally:
        os.environ.pop("BASALT_REFERENCE_DIR", None)
        if saved is not None:
            os.environ["BASALT_REFERENCE_DIR"] = saved


def test_interp():
    t, y = [0.0, 1.0, 3.0], [10.0, 20.0, 0.0]
    assert bt.interp(t, y, -1.0) == 10.0 and bt.interp(t, y, 5.0) == 0.0, "held beyond the ends"
    assert bt.interp(t, y, 1.0) == 20.0 and close(bt.interp(t, y, 0.25), 12.5) and close(bt.interp(t, y, 2.0), 10.0)


def test_mpi():
    s = bt.mpi_settings()
    assert s["OMPI_ALLOW_RUN_AS_ROOT"] == "1" and s["HWLOC_COMPONENTS"] == "-gl", s
    assert s["OMPI_MCA_mpi_yield_when_idle"] == "1" and s["OMPI_MCA_hwloc_base_binding_policy"] == "none", s
    env = bt.mpi_env(base={"OMPI_ALLOW_RUN_AS_ROOT": "0"})
    assert {k: env[k] for k in s} == s, env
    env = bt.mpi_env(bt.RUN_AS_ROOT, override=False, base={"OMPI_ALLOW_RUN_AS_ROOT": "0"}, X="1")
    assert env == {"OMPI_ALLOW_RUN_AS_ROOT": "0", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
                   "OMPI_MCA_rmaps_base_oversubscribe": "1", "X": "1"}, env
    env = bt.mpi_env((), ranks=1, eager=True, base={"OMPI_MCA_btl_vader_eager_limit": "4096"})
    assert env == {"OMPI_MCA_mpi_yield_when_idle": "0", "OMPI_MCA_btl_vader_eager_limit": "4096",
                   "OMPI_MCA_btl_vader_max_send_size": "65536"}, env
    assert "OMPI_MCA_mpi_yield_when_idle" not in bt.mpi_env((), ranks=10 ** 6, base={})
    assert bt.basalt_run_command("r", "s.toml", "--steps", 5) == ["r", "s.toml", "--steps", "5"]
    assert bt.basalt_run_command("r", "s", np=2, timed=True) == ["/usr/bin/time", "-v", "mpirun", "-np", "2", "r", "s"]
    assert bt.basalt_run_command("r", "s", np=3, launcher="mpiexec", flag="-n")[:3] == ["mpiexec", "-n", "3"]
    assert bt.parse_dims("2,1,1") == [2, 1, 1]
    for bad in ("2,1", "0,1,1", "a,1,1"):
        try:
            bt.parse_dims(bad)
            raise AssertionError(bad)
        except ValueError:
            pass
    env = bt.esys_env()
    assert env[bt.ESYS_CHILD_ENV] == "1" and "OMPI_MCA_rmaps_base_oversubscribe" in env
    assert bt.esys_command("x.py", 3, ["--a"])[:5] == ["mpirun", "-np", "3", "esysparticle", os.path.abspath("x.py")]


def live_run(exe):
    """basalt-run itself, 20 steps of the wave on cube1.geo, 1 rank: its lines still parse."""
    with tempfile.TemporaryDirectory() as d:
        p = bt.run(bt.basalt_run_command(exe, os.path.join(ROOT, "scenes", "wave.toml"), "--geometry", CUBE,
                                         "--steps", 20, "--output", d, "--fields-every", 1), timed=True)
        r = bt.parse_run(p.stdout)
        for key in ("particles", "dt", "critical_step", "field_bytes", "loop_s", "particle_steps_per_s", "rebuilds",
                    "cpu_s", "phases", "bytes_per_particle", "output", "compute_wait_s"):
            assert key in r, f"basalt-run's output has no '{key}' for the parser:\n{p.stdout}"
        assert r["particles"] == 8948 and r["loop_steps"] == 20 and list(r["phases"]) == PHASES, r
        # the forces phase by model kind: the wave's bonds, contacts and wall, no body force; their sum is
        # within the forces phase (printed to 0.1 us: rounding)
        kinds = r["force_kinds"]
        assert list(kinds) == ["bond", "pair", "wall", "body force"] and kinds["bond"] > 0, kinds
        assert kinds["body force"] == 0 and sum(kinds.values()) <= r["phases"]["forces"][0] + 4e-4, (kinds, r)
        assert p.time["max_rss_kb"] > 0 and p.time["exit_status"] == 0, p.time
        c = bt.read_fields(d)
        assert c["step"] == list(range(1, 21)) and "kinetic_energy" in c, c


def main():
    return run_tests(globals(), [("live_run", lambda: live_run(sys.argv[1]))] if len(sys.argv) > 1 else [])


if __name__ == "__main__":
    sys.exit(main())
