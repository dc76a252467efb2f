"""basalt-study (tools/study/, docs/accuracy.md "Your own scene: basalt-study") on a tiny collapsing pile.

One study (a reference, 2 perturbed references, 2 settings, ~30 s) is shared by the tests: every setting is
reported, the reference has zero error, a far too large dt fraction is worse than the ensemble's spread, a
second call resumes without running again, and bad input stops with exit status 2 and a message naming it.
The modules' own pieces (scene overrides, TOML writer, quantities, the perturbation) are tested directly.
"""
import json
import sys
import tomllib

import numpy as np
import pytest

from conftest import BIN, ROOT, run

sys.path.insert(0, str(ROOT / "tools" / "study"))
import perturb  # noqa: E402
import quantities  # noqa: E402
import scene_overrides  # noqa: E402

# A 6 x 4 x 6 pile of grains (radii 0.4-0.6, ~94 of them) collapsing along +x under gravity, in a channel:
# scenes/column-collapse.toml in small.
SCENE = """
[geometry]
file = "pile.h5"

[particles]
rotation = true

[run]
dt = 0.0025
steps = 400
skin = 0.2

[[interactions]]
name = "grains"
type = "rot_friction"
K = 2000.0
Ks = 1000.0
mu = 0.5

[[walls]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
interaction = "friction"
K = 2000.0
Ks = 1000.0
mu = 0.5

[[walls]]
name = "back"
point = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
K = 2000.0

[[walls]]
name = "side_y0"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
K = 2000.0

[[walls]]
name = "side_yW"
point = [0.0, 4.0, 0.0]
normal = [0.0, -1.0, 0.0]
K = 2000.0

[[body_forces]]
type = "gravity"
acceleration = [0.0, 0.0, -1.0]

[output]
directory = "out"

[[output.fields]]
type = "kinetic_energy"

[[output.fields]]
type = "runout"
"""
QUANTITIES = ["-q", "fields.runout_max:last", "-q", "checkpoint.position.z:mean"]
LADDER = ["--dt-fraction", "0.2,0.9", "--ensemble", "2"]
SETTINGS = ["reference", "ensemble1", "ensemble2", "double-dtf0.2-k1-skin0.2", "double-dtf0.9-k1-skin0.2"]


def study_cmd(scene, out, *extra):
    return [BIN / "basalt-study", scene, *QUANTITIES, *LADDER, "-o", out, *extra]


@pytest.fixture(scope="module")
def pile(tmp_path_factory, bin_dir):
    d = tmp_path_factory.mktemp("study")
    run([bin_dir / "basalt-pack", "box", "--size", "6,4,6", "--rmin", "0.4", "--rmax", "0.6", "--no-bonds",
         "--seed", "3", "-o", d / "pile.h5"])
    (d / "scene.toml").write_text(SCENE)
    if not (bin_dir / "basalt-study").exists():
        pytest.fail(f"{bin_dir / 'basalt-study'} is missing: build it (tools/study/CMakeLists.txt)")
    return d


@pytest.fixture(scope="module")
def study(pile):
    out = pile / "study"
    p = run(study_cmd(pile / "scene.toml", out, "--budget", "1e-4"))
    return p, out, json.loads((out / "study.json").read_text())


def by_key(summary):
    return {r["key"]: r for r in summary["runs"]}


def test_every_setting_is_reported(study):
    p, out, summary = study
    assert sorted(by_key(summary)) == sorted(SETTINGS)
    table = (out / "table.md").read_text()
    for key in SETTINGS:
        assert f"| {key} |" in table
    assert (out / "study.png").stat().st_size > 1000
    assert "[5/5]" in p.stdout and "ETA" in p.stdout
    assert all(r["status"] == "ok" for r in summary["runs"])


def test_reference_has_zero_error_and_members_its_dt(study):
    _, _, summary = study
    runs = by_key(summary)
    ref = runs["reference"]
    assert all(e == 0.0 for e in ref["errors"].values())
    assert ref["speedup"] == 1.0
    for m in ("ensemble1", "ensemble2"):
        assert runs[m]["dt"] == ref["dt"]
        assert runs[m]["steps"] == ref["steps"]
    # The nudge is real: the members differ from the reference, a little.
    for spec, spread in summary["spread"].items():
        assert spread > 0, spec
        assert spread < 1e-4 * abs(ref["quantities"][spec]), spec


def test_too_large_a_step_is_worse_than_the_chaos_floor(study):
    _, _, summary = study
    runs = by_key(summary)
    bad, good = runs["double-dtf0.9-k1-skin0.2"], runs["double-dtf0.2-k1-skin0.2"]
    for spec, spread in summary["spread"].items():
        err = abs(bad["quantities"][spec] - runs["reference"]["quantities"][spec])
        assert err > 10 * spread, spec
        assert bad["noise"][spec] > 10
        assert bad["errors"][spec] > good["errors"][spec]
    assert bad["max_error"] > 1e-4 and good["max_error"] < 1e-4
    assert summary["cheapest"] in ("reference", good["key"])  # which of the two is cheaper is the machine's say


def test_budget_names_the_cheapest_setting_and_writes_a_fragment(study):
    _, out, summary = study
    runs = by_key(summary)
    best = runs[summary["cheapest"]]
    assert all(e <= 1e-4 or best["noise"][s] <= 1 for s, e in best["errors"].items())
    fragment = tomllib.loads((out / "setting.toml").read_text())
    assert fragment["run"]["dt_fraction"] == best["setting"]["dt_fraction"]
    assert fragment["run"]["precision"] == best["setting"]["precision"]


def test_resume_skips_finished_settings(study, pile):
    _, out, _ = study
    victim = out / "runs" / "double-dtf0.2-k1-skin0.2" / "result.json"
    kept = {k: (out / "runs" / k / "result.json").stat().st_mtime_ns for k in SETTINGS}
    victim.unlink()  # as if the study had been stopped during this setting
    p = run(study_cmd(pile / "scene.toml", out, "--no-plot"))
    for k in SETTINGS:
        if k == "double-dtf0.2-k1-skin0.2":
            assert f"{k}: double dtf 0.2" in p.stdout  # run again
        else:
            assert f"{k}: finished earlier, kept" in p.stdout
            assert (out / "runs" / k / "result.json").stat().st_mtime_ns == kept[k]
    assert victim.exists()
    p = run(study_cmd(pile / "scene.toml", out, "--no-plot"))
    assert p.stdout.count("finished earlier, kept") == len(SETTINGS)


@pytest.mark.parametrize("args, named", [
    (["-q", "fields.no_such_column:last"], "no_such_column"),
    (["-q", "fields.runout_max:median"], "median"),
    (["-q", "checkpoint.no_such_dataset:mean"], "no_such_dataset"),
    (["-q", "volume:mean"], "volume"),
    (["--budget", "cheap"], "--budget"),
    (["--budget", "-1e-2"], "--budget"),
    (["--precision", "quad"], "quad"),
    (["--stiffness", "0,1"], "--stiffness"),
])
def test_bad_input_is_named(pile, args, named):
    cmd = [BIN / "basalt-study", pile / "scene.toml", "-o", pile / "bad", "--ensemble", "1"] + args
    if "-q" not in args:
        cmd += ["-q", "fields.runout_max:last"]
    p = run(cmd, check=False)
    assert p.returncode == 2, p.stdout + p.stderr
    assert "basalt-study: error:" in p.stderr and named in p.stderr, p.stderr
    assert not (pile / "bad" / "table.md").exists()


def test_missing_scene_key_is_named(pile, tmp_path):
    (tmp_path / "s.toml").write_text(SCENE.replace('file = "pile.h5"', 'name = "x"'))
    p = run([BIN / "basalt-study", tmp_path / "s.toml", "-q", "fields.runout_max:last", "-o", tmp_path / "o"],
            check=False)
    assert p.returncode == 2 and "geometry.file" in p.stderr, p.stderr
    (tmp_path / "s.toml").write_text(SCENE.replace("skin = 0.2", "").replace('"pile.h5"', f'"{pile}/pile.h5"'))
    p = run([BIN / "basalt-study", tmp_path / "s.toml", "-q", "fields.runout_max:last", "-o", tmp_path / "o2"],
            check=False)
    assert p.returncode == 2 and "run.skin" in p.stderr, p.stderr


# ------------------------------------------------------------------------------------------------ the pieces


def test_stiffness_scale_touches_contacts_only():
    scene = tomllib.loads(SCENE)
    scene["interactions"].append({"type": "linear_bond", "K": 7.0})
    scene["interactions"].append({"type": "hertz_mindlin", "E": 1e5})
    s = scene_overrides.apply(scene, dt_fraction=0.3, stiffness=0.01, skin=0.5)
    assert s["interactions"][0]["K"] == 20.0 and s["interactions"][0]["Ks"] == 10.0
    assert s["interactions"][1]["K"] == 7.0                       # a bond is not a contact
    assert s["interactions"][2]["E"] == pytest.approx(1e3)
    assert [w["K"] for w in s["walls"]] == [20.0] * 4 and s["walls"][0]["Ks"] == 10.0
    assert "dt" not in s["run"] and s["run"]["dt_fraction"] == 0.3 and s["run"]["skin"] == 0.5
    assert scene["interactions"][0]["K"] == 2000.0                # the scene itself is left alone
    no_contacts = {"run": {"dt": 1.0}, "interactions": [{"type": "linear_bond", "K": 1.0}]}
    with pytest.raises(scene_overrides.SceneError, match="no contact model"):
        scene_overrides.apply(no_contacts, stiffness=0.1)


def test_toml_writer_round_trips():
    scene = tomllib.loads(SCENE)
    scene["stages"] = [{"name": "a", "steps": 3, "until": {"kinetic_energy_below": 1e-6, "every": 10}}]
    scene["walls"][0]["motion"] = {"type": "sine", "amplitude": 0.1, "period": 1.0}
    scene["output"]["render"] = 'color="speed"\n'
    assert tomllib.loads(scene_overrides.dumps(scene)) == scene


def test_quantities_reduce_as_named():
    t = np.array([0.0, 1.0, 2.0, 3.0])
    fields = {"time": t, "a": np.array([1.0, 5.0, 3.0, np.nan]), "step": t}
    assert quantities.Quantity("fields.a:last").measure(fields, None, 0, 1.5) == 4.0
    assert quantities.Quantity("fields.a:max").measure(fields, None, 0, 3) == 5.0
    assert quantities.Quantity("fields.a:mean").measure(fields, None, 1, 2) == 4.0

    # A loading curve: force rising linearly at 10 per unit time to a peak 50 at t = 5, then falling; bonds
    # breaking in two columns.
    t = np.arange(0.0, 10.5, 0.5)
    force = np.where(t <= 5, 10 * t, 50 - 20 * (t - 5))
    fields = {"time": t, "step": t, "f": force, "b1": np.floor(t), "b2": 2 * np.floor(t)}
    assert quantities.Quantity("fields.f:argmax").measure(fields, None, 0, 10) == 5.0
    assert quantities.Quantity("fields.f:argmin").measure(fields, None, 0, 10) == 10.0
    assert quantities.Quantity("fields.f:argmax").measure(fields, None, 0, 4) == 4.0
    assert quantities.Quantity("fields.f:half_max_slope").measure(fields, None, 0, 10) == pytest.approx(10.0)
    assert quantities.Quantity("fields.b1+b2:at_max(f)").measure(fields, None, 0, 10) == 15.0
    assert quantities.Quantity("fields.b1:at_max(f)*1.2").measure(fields, None, 0, 10) == 6.0
    assert quantities.Quantity("fields.f:at_max(f)*1.25").measure(fields, None, 0, 10) == pytest.approx(25.0)
    assert quantities.Quantity("fields.f:at_min(b1+b2)").measure(fields, None, 2, 10) == 20.0
    with pytest.raises(quantities.QuantityError, match="past the last saved row"):
        quantities.Quantity("fields.b1:at_max(f)*3").measure(fields, None, 0, 10)
    with pytest.raises(quantities.QuantityError, match="positive number"):
        quantities.Quantity("fields.b1:at_max(f)*0")
    with pytest.raises(quantities.QuantityError, match="no field 'g'"):
        quantities.Quantity("fields.b1:at_max(f+g)").check_fields(["step", "time", "f", "b1"])
    with pytest.raises(quantities.QuantityError, match="unknown reduction"):
        quantities.Quantity("fields.f:at_mid(b1)")

    class Ckpt:
        particles = {"position": np.array([[0, 0, 1.0], [0, 0, 2.0], [3, 4, 3.0]]), "radius": np.ones(3)}
        bonds = {"broken": np.array([0, 1, 1, 0])}

    c = Ckpt()
    assert quantities.Quantity("checkpoint.position.z:count>1.5").measure(None, c, 0, 1) == 2
    assert quantities.Quantity("checkpoint.position.norm:max").measure(None, c, 0, 1) == pytest.approx(34 ** 0.5)
    assert quantities.Quantity("checkpoint.position.z:p50").measure(None, c, 0, 1) == 2.0
    assert quantities.Quantity("checkpoint.bonds.broken:count").measure(None, c, 0, 1) == 2
    with pytest.raises(quantities.QuantityError, match="is a vector"):
        quantities.Quantity("checkpoint.position:mean").measure(None, c, 0, 1)
    with pytest.raises(quantities.QuantityError, match="percentile"):
        quantities.Quantity("checkpoint.radius:p101")


def test_rate_and_damping_scale_what_they_name():
    scene = tomllib.loads(SCENE)
    scene["walls"][1]["motion"] = {"type": "ramp", "velocity": [0.1, 0.0, 0.0], "ramp_time": 2.0, "start_time": -1.0}
    scene["walls"][2]["motion"] = {"type": "servo", "target_force": 1.0, "gain": 1.0, "max_speed": 0.1}
    scene["body_forces"].append({"type": "linear_damping", "viscosity": 0.5})
    s = scene_overrides.apply(scene, rate=4.0, damping=0.1)
    assert s["walls"][1]["motion"] == {"type": "ramp", "velocity": [0.4, 0.0, 0.0], "ramp_time": 0.5,
                                       "start_time": -0.25}
    assert s["walls"][2]["motion"] == scene["walls"][2]["motion"]  # a servo follows a force, not a clock
    assert s["body_forces"][1]["viscosity"] == pytest.approx(0.05)
    assert scene["walls"][1]["motion"]["velocity"] == [0.1, 0.0, 0.0]  # the user's scene is not touched
    with pytest.raises(scene_overrides.SceneError, match="no wall with a prescribed motion"):
        scene_overrides.apply(tomllib.loads(SCENE), rate=2.0)
    with pytest.raises(scene_overrides.SceneError, match="no damping"):
        scene_overrides.apply(tomllib.loads(SCENE), damping=2.0)
    scene["body_forces"].append({"type": "local_damping", "alpha": 0.3})
    with pytest.raises(scene_overrides.SceneError, match="alpha x 4 = 1.2"):
        scene_overrides.apply(scene, damping=4.0)


def test_a_faster_loading_reaches_the_same_state_in_less_time(pile):
    """A piston closing at constant speed: at rate x2 the run lasts half as long, and the study reads its times
    as the scene's loading time, so the piston's final position and the time of its largest x agree with the
    scene's own rate (the piston touches nothing: no physics changes with the rate)."""
    scene = tomllib.loads(SCENE)
    scene["walls"].append({"name": "piston", "point": [20.0, 0.0, 0.0], "normal": [-1.0, 0.0, 0.0], "K": 2000.0,
                           "motion": {"type": "constant_velocity", "velocity": [-1.0, 0.0, 0.0]}})
    scene["output"]["fields"] = [{"type": "wall_position", "wall": "piston"}]
    (pile / "piston.toml").write_text(scene_overrides.dumps(scene))
    out = pile / "study-rate"
    run([BIN / "basalt-study", pile / "piston.toml", "-q", "fields.wall_position_piston_x:last",
         "-q", "fields.wall_position_piston_x:argmin", "--steps", "200", "--dt-fraction", "0.02", "--rate", "1,2",
         "--ensemble", "1", "--no-plot", "-o", out])
    runs = by_key(json.loads((out / "study.json").read_text()))
    ref, fast = runs["reference"], runs["double-dtf0.02-k1-skin0.2-rate2"]
    assert fast["setting"]["rate"] == 2.0 and fast["dt"] == ref["dt"]
    assert fast["steps"] == pytest.approx(ref["steps"] / 2, abs=1)
    t_end = 200 * 0.0025  # the window: 200 of the scene's steps
    for r in (ref, fast):
        assert r["quantities"]["fields.wall_position_piston_x:last"] == pytest.approx(20.0 - t_end, rel=1e-12)
        # the last saved row inside the window, in the scene's time
        assert r["quantities"]["fields.wall_position_piston_x:argmin"] == pytest.approx(t_end, abs=2 * ref["dt"])
    assert fast["sim_time"] == pytest.approx(ref["sim_time"], rel=1e-9)  # the scene's loading time, not the run's
    table = (out / "table.md").read_text()
    assert "| rate |" in table and "| double-dtf0.02-k1-skin0.2-rate2 | double | 0.02 | 1 | 0.2 | 2 |" in table


def test_presets_run_as_basalt_run_sets_them(pile):
    """--presets: each preset is run by basalt-run --preset (its precision and dt fraction are the solver's, read
    back from the run), and reported like any setting."""
    out = pile / "study-presets"
    run([BIN / "basalt-study", pile / "scene.toml", "-q", "fields.kinetic_energy:max", "--steps", "100",
         "--dt-fraction", "0.2", "--presets", "--ensemble", "1", "--no-plot", "-o", out])
    runs = by_key(json.loads((out / "study.json").read_text()))
    chosen = {k: (runs[f"preset-{k}"]["setting"]["precision"], runs[f"preset-{k}"]["setting"]["dt_fraction"])
              for k in ("fast", "balanced", "reference")}
    assert chosen == {"fast": ("float", 0.5), "balanced": ("double", 0.25), "reference": ("double", 0.05)}
    assert runs["preset-reference"]["steps"] == pytest.approx(10 * runs["preset-fast"]["steps"], rel=0.02)
    assert runs["preset-balanced"]["dt"] == pytest.approx(0.25 / 0.2 * runs["double-dtf0.2-k1-skin0.2"]["dt"], rel=1e-9)
    table = (out / "table.md").read_text()
    assert "| preset-fast | float | 0.5 |" in table


def test_perturbed_members_move_by_the_nudge_alone(pile, tmp_path):
    import basalt
    base = basalt.read_geometry(str(pile / "pile.h5"))
    assert perturb.write_member(str(pile / "pile.h5"), str(tmp_path / "m0.h5"), 0) == 0.0
    assert perturb.write_member(str(pile / "pile.h5"), str(tmp_path / "m1.h5"), 1) == pytest.approx(1e-9)
    m0, m1 = (basalt.read_geometry(str(tmp_path / f"m{k}.h5")) for k in (0, 1))
    assert np.array_equal(m0.positions, base.positions)
    d = np.linalg.norm(m1.positions - base.positions, axis=1) / base.particles["radius"]
    assert d.min() > 0.5e-9 and d.max() < 1.5e-9
    for key in ("id", "radius", "tag"):
        assert np.array_equal(m1.particles[key], base.particles[key])


def test_errors_spread_pareto_and_budget_on_made_up_runs():
    import study_report

    def r(key, kind, q, cpu, k=1.0):
        return {"key": key, "kind": kind, "status": "ok", "quantities": {"q": q}, "cpu_s": cpu, "ranks": 1,
                "sim_time": 1.0, "setting": {"precision": "double", "dt_fraction": 0.1, "stiffness": k, "skin": 0.1},
                "dt": 0.1, "steps": 10, "sim_time_per_cpu_s": 1 / cpu, "particle_steps_per_s": 1e6,
                "rss_bytes_per_particle": 1e3}

    runs = [r("reference", "reference", 10.0, 8.0), r("ensemble1", "ensemble", 10.01, 8.0),
            r("ensemble2", "ensemble", 9.98, 8.0), r("a", "setting", 10.015, 4.0),   # inside the noise
            r("b", "setting", 10.5, 1.0, k=0.1), r("c", "setting", 10.5, 2.0),       # c: dominated by b
            {"key": "d", "kind": "setting", "status": "failed", "message": "blow-up",
             "setting": {"precision": "float", "dt_fraction": 1.0, "stiffness": 1.0, "skin": 0.1}}]
    ref, spreads = study_report.evaluate(runs, ["q"])
    assert spreads["q"] == pytest.approx(0.02)
    a, b = runs[3], runs[4]
    assert a["errors"]["q"] == pytest.approx(1.5e-3) and a["noise"]["q"] == pytest.approx(0.75)
    assert b["errors"]["q"] == pytest.approx(0.05) and b["noise"]["q"] == pytest.approx(25)
    assert b["speedup"] == 8.0 and ref["speedup"] == 1.0
    table = [x for x in runs if x["kind"] != "ensemble"]
    study_report.pareto(table)
    assert [x["key"] for x in table if x.get("pareto")] == ["reference", "a", "b"]
    assert study_report.cheapest(table, 1e-4)["key"] == "a"      # above the budget, but inside the noise
    assert study_report.cheapest(table, 0.1)["key"] == "b"
    text = study_report.markdown(runs, ["q"], spreads, ref, 0.1, b)
    assert "| d |" in text and "blow-up" in text and "**cheapest within budget**" in text
    fragment = study_report.fragment(b, tomllib.loads(SCENE), "scene.toml", 0.1)
    assert 'interactions[0] "grains": K = 200.0' in fragment and 'walls[3] "side_yW": K = 200.0' in fragment
