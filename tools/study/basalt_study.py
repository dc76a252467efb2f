#!/usr/bin/python3
"""basalt-study: speed against accuracy on the user's own scene (issue 46; docs/accuracy.md, "Your own scene").

    basalt-study SCENE.toml -q fields.runout_max:last -q checkpoint.position.z:p99 --steps 4000 \\
        --dt-fraction 0.05,0.2,0.5 --precision double,float --stiffness 1,0.1 --budget 1e-2 -o study/

Runs the scene over a window of simulated time (--steps N: N steps of the scene's own dt; or --time T) as
  * the reference: double, --reference-dt-fraction (0.02), the scene's stiffness and skin;
  * an ensemble of --ensemble M (3) references whose positions are nudged by 1e-9 of each radius (perturb.py),
    run with the reference's dt (a nudge may open or close a contact at the start, and so change the critical
    step estimated there by a percent): their spread is the scene's chaos floor;
  * every setting of the ladder, the product of --precision x --dt-fraction x --stiffness x --skin (each one a
    scene written to the study's folder, scene_overrides.py);
and reports each quantity's error against the reference and as a multiple of the spread, the speed-up
(CPU time per simulated time, against the reference's, measured in the same study), basalt-run's own
particle-steps/s and peak RSS per particle: OUT/table.md, OUT/study.json, OUT/study.png, and with --budget the
cheapest setting within it and OUT/setting.toml, a fragment to paste into the scene.
Finished runs are kept in OUT/runs/<name>/ (result.json, fields.csv, the last checkpoint): the same command
again skips them (stop with Ctrl-C and resume). Bad input stops with a message naming it and exit status 2.
"""
import argparse
import hashlib
import itertools
import math
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, ".."))
import basalt_tools as bt  # noqa: E402  (tools/basalt_tools.py)
import perturb  # noqa: E402
import quantities as qty  # noqa: E402
import scene_overrides as so  # noqa: E402
import study_report as rep  # noqa: E402

PRECISIONS = ("double", "float", "mixed")


class StudyError(Exception):
    """Bad input: printed as 'basalt-study: error: ...', exit status 2."""


def numbers(text, option, positive=True):
    out = []
    for word in text.split(","):
        try:
            v = float(word)
        except ValueError:
            raise StudyError(f"{option}: '{word}' is not a number (give a comma-separated list, e.g. 0.1,0.2)")
        if positive and not (v > 0 and math.isfinite(v)):
            raise StudyError(f"{option}: {word} must be a positive number")
        out.append(v)
    return out


def parse_args(argv):
    p = argparse.ArgumentParser(prog="basalt-study", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", help="the scene (TOML, docs/scenes.md)")
    p.add_argument("-q", "--quantity", action="append", default=[], metavar="SPEC",
                   help="a quantity of interest (repeatable): fields.COLUMN[+COLUMN...]:last|max|min|mean|argmax|"
                        "argmin|half_max_slope|at_max(C)[*F]|at_min(C)[*F] or "
                        "checkpoint.DATASET[.x|y|z|norm]:mean|max|min|sum|pP|count|count>V|count<V "
                        "(tools/study/quantities.py)")
    w = p.add_mutually_exclusive_group()
    w.add_argument("--steps", type=int, help="window: this many steps of the scene's own dt (default run.steps)")
    w.add_argument("--time", type=float, help="window: this much simulated time")
    p.add_argument("--window-start", type=float, default=0.0,
                   help="fields reduced by max/min/mean over [this time, window end] (default 0)")
    p.add_argument("--dt-fraction", help="ladder: run.dt_fraction values (default: the scene's own)")
    p.add_argument("--precision", help="ladder: double,float,mixed (default: the scene's)")
    p.add_argument("--stiffness", help="ladder: contact-stiffness scales (default 1)")
    p.add_argument("--skin", help="ladder: run.skin values (default: the scene's)")
    p.add_argument("--rate", help="ladder: loading-rate scales of the walls' prescribed motions (default 1); the "
                                  "window of a run at S is the scene's over S, and its fields' times are "
                                  "multiplied by S (so a time reads as the scene's loading time)")
    p.add_argument("--damping", help="ladder: scales of the body-force damping (default 1)")
    p.add_argument("--presets", action="store_true",
                   help="also run basalt-run's presets (--preset fast, balanced, reference: docs/stability.md) as "
                        "settings, to measure their error on this scene")
    p.add_argument("--reference-dt-fraction", type=float, default=0.02, help="the reference's dt fraction (0.02)")
    p.add_argument("--ensemble", type=int, default=3, help="perturbed references (default 3)")
    p.add_argument("--perturbation", type=float, default=1e-9, help="their nudge, fraction of the radius (1e-9)")
    p.add_argument("--budget", help="report the cheapest setting whose every error is <= this (or inside the noise)")
    p.add_argument("--geometry", help="geometry file; overrides the scene's geometry.file")
    p.add_argument("-o", "--out", help="the study's folder (default study-<scene name>)")
    p.add_argument("--np", type=int, default=1, help="compute ranks per run (default 1)")
    p.add_argument("--rows", type=int, default=1000, help="field rows saved over the window (default 1000)")
    p.add_argument("--no-plot", action="store_true", help="no study.png (matplotlib is not imported)")
    p.add_argument("--bin", help="folder of basalt-run (default build/bin of the checkout)")
    return p.parse_args(argv)


def check_args(a):
    if not a.quantity:
        raise StudyError("name at least one quantity of interest: -q fields.COLUMN:REDUCTION (see --help)")
    a.quantities = [qty.Quantity(s) for s in a.quantity]
    if a.budget is not None:
        try:
            a.budget = float(a.budget)
        except ValueError:
            raise StudyError(f"--budget: '{a.budget}' is not a number (a relative error, e.g. 1e-2)")
        if not (a.budget > 0 and math.isfinite(a.budget)):
            raise StudyError(f"--budget: {a.budget:g} must be a positive relative error, e.g. 1e-2")
    if a.precision:
        a.precision = a.precision.split(",")
        for v in a.precision:
            if v not in PRECISIONS:
                raise StudyError(f"--precision: '{v}' is not one of {', '.join(PRECISIONS)}")
    for name in ("dt_fraction", "stiffness", "skin", "rate", "damping"):
        v = getattr(a, name)
        if v is not None:
            setattr(a, name, numbers(v, "--" + name.replace("_", "-")))
    if not a.reference_dt_fraction > 0:
        raise StudyError("--reference-dt-fraction must be positive")
    for name, low in (("ensemble", 1), ("np", 1), ("rows", 1)):
        if getattr(a, name) < low:
            raise StudyError(f"--{name} must be >= {low}")
    if a.steps is not None and a.steps < 1:
        raise StudyError("--steps must be >= 1")
    if a.time is not None and not a.time > 0:
        raise StudyError("--time must be positive")


def sha(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()[:16]


def cpu_name():
    model, flags = "unknown CPU", []
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name") and model == "unknown CPU":
                    model = line.split(":", 1)[1].strip()
                elif line.startswith("flags") and not flags:
                    have = line.split(":", 1)[1].split()
                    flags = [x for x in ("sse4_2", "avx", "avx2", "fma", "avx512f") if x in have]
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} cores, {' '.join(flags) or 'no AVX'}"


class Study:
    def __init__(self, a):
        self.a = a
        self.exe = bt.binary("basalt-run", bin=a.bin)
        if not os.path.exists(self.exe):
            raise StudyError(f"basalt-run not found at {self.exe} (build it, or give --bin)")
        self.scene_path = a.scene
        self.scene = so.absolute_paths(so.load(a.scene), a.scene, a.geometry)
        self.geometry = self.scene["geometry"]["file"]
        if not os.path.exists(self.geometry):
            raise StudyError(f"geometry.file: {self.geometry}: no such file")
        stem = os.path.splitext(os.path.basename(a.scene))[0]
        self.out = os.path.abspath(a.out or f"study-{stem}")
        self.env = bt.mpi_env(ranks=a.np)

    def say(self, text):
        print(f"basalt-study: {text}", flush=True)

    # ------------------------------------------------------------------------------------------- runs

    def command(self, scene_file, out, precision, steps, every, preset=None):
        # A preset sets the precision and dt fraction itself (basalt-run --preset): those are its own.
        chosen = ["--preset", preset] if preset else ["--precision", precision]
        return bt.basalt_run_command(self.exe, scene_file, "--steps", steps, "--output", out, *chosen,
                                     "--fields-every", every, "--checkpoint-every", max(1, steps),
                                     "--frames-every", 0, "--quiet", np=self.a.np, timed=True)

    def write_scene(self, folder, setting, geometry, dt=None):
        s = so.apply(self.scene, setting["dt_fraction"], setting["stiffness"], setting["skin"], self.scene_path, dt,
                     rate=setting.get("rate", 1.0), damping=setting.get("damping", 1.0))
        s["geometry"]["file"] = geometry
        os.makedirs(folder, exist_ok=True)
        path = os.path.join(folder, "scene.toml")
        with open(path, "w") as f:
            f.write(so.dumps(s))
        return path

    def probe(self, folder, scene_file, precision, preset=None):
        """basalt-run for one step: the dt, critical step and particles of a setting, the fields' columns.
        Kept in FOLDER/probe.json (the study's plan.json vouches for the scene and geometry)."""
        out, kept = os.path.join(folder, "probe"), os.path.join(folder, "probe.json")
        if os.path.exists(kept):
            info = load_json(kept)
            if info.get("checkpoint") is None or os.path.exists(info["checkpoint"]):  # not a moved folder
                return info, None
        p = bt.run(self.command(scene_file, out, precision, 1, 1, preset), check=False, env=self.env)
        info = bt.parse_run(p.stdout)
        if p.returncode != 0 or "dt" not in info:
            return None, failure(p)
        with open(os.path.join(out, "fields.csv")) as f:
            info["columns"] = f.readline().strip().split(",")
        info["checkpoint"] = bt.last_checkpoint(out)
        rep.write_json(kept, info)
        return info, None

    def run(self, run, k, total):
        folder = os.path.join(self.out, "runs", run["key"])
        done = os.path.join(folder, "result.json")
        if os.path.exists(done):
            self.say(f"[{k}/{total}] {run['key']}: finished earlier, kept ({done})")
            return load_json(done)
        begun = time.time()  # the probe's time too, for the ETA
        geometry = self.members[run.get("member", 0)]
        scene_file = self.write_scene(folder, run["setting"], geometry, run.get("fixed_dt"))
        if run.get("fixed_dt"):  # an ensemble member: the reference's dt and particles, no probe needed
            info = {"dt": run["fixed_dt"], "particles": run["particles"]}
        else:
            preset = run["setting"].get("preset")
            info, err = self.probe(folder, scene_file, run["setting"]["precision"], preset)
            if info is None:
                return self.finish(done, run, status="failed", message=err)
            if preset:  # what the preset chose, for the table and the fragment
                run["setting"].update(precision=info["precision"],
                                      dt_fraction=float(f"{info['dt'] / info['critical_step']:.3g}"))
        dt = info["dt"]
        rate = run["setting"].get("rate", 1.0)
        t_end = self.t_end / rate  # a faster loading reaches the scene's state sooner
        every = max(1, round(t_end / (dt * self.a.rows)))
        steps = every * math.ceil(t_end / (dt * every) - 1e-9)
        run.update(dt=dt, steps=steps, every=every, critical_step=info.get("critical_step"),
                   particles=info["particles"], ranks=self.a.np)
        self.say(f"[{k}/{total}] {run['key']}: {rep.label(run)}: {steps} steps of dt = {dt:.4g}"
                 + self.eta(total - k + 1, steps * info["particles"]))
        out = os.path.join(folder, "run")
        start = time.time()
        p = bt.run(self.command(scene_file, out, run["setting"]["precision"], steps, every,
                                run["setting"].get("preset")), check=False,
                   env=self.env)
        wall = time.time() - start
        self.spent += time.time() - begun
        self.work_done += steps * info["particles"]
        x, tv = bt.parse_run(p.stdout), bt.parse_time_v(p.stderr)
        if p.returncode != 0 or "cpu_s" not in x:
            self.say(f"  {run['key']} failed after {wall:.1f} s: {failure(p)}")
            return self.finish(done, run, status="failed", message=failure(p))
        run.update(status="ok", wall_s=wall, cpu_s=x["cpu_s"], loop_s=x["loop_s"],
                   particle_steps_per_s=x["particle_steps_per_s"], sim_time=steps * dt * rate,
                   sim_time_per_cpu_s=steps * dt * rate / (x["cpu_s"] * self.a.np) if x["cpu_s"] > 0 else float("nan"),
                   max_rss_kb=tv.get("max_rss_kb", float("nan")),
                   rss_bytes_per_particle=tv.get("max_rss_kb", float("nan")) * 1024.0 / info["particles"],
                   array_bytes_per_particle=x.get("bytes_per_particle"), output=out)
        run["quantities"] = self.measure(run)
        self.say(f"  done in {wall:.1f} s ({x['particle_steps_per_s'] / 1e6:.2f} M particle-steps/s): "
                 + ", ".join(f"{s} = {v:.6g}" for s, v in run["quantities"].items()))
        return self.finish(done, run)

    def finish(self, path, run, **extra):
        run.update(extra)
        run.setdefault("status", "ok")
        rep.write_json(path, run)
        return run

    def eta(self, runs_left, work):
        if self.work_done == 0:
            return ""
        rate = self.spent / self.work_done
        left = rate * (work + self.work_left_after(runs_left))
        return f" (ETA {fmt_s(left)})"

    def work_left_after(self, runs_left):
        # The runs after this one, each guessed as large as the mean run so far.
        return (runs_left - 1) * self.work_done / max(1, self.runs_timed)

    def measure(self, run):
        import basalt
        fields = basalt.read_fields(os.path.join(run["output"], "fields.csv"))
        cols = {n: fields[n] for n in fields.dtype.names}
        # At loading rate S a time t of the run is the scene's loading time S t (run["sim_time"] likewise).
        cols["time"] = cols["time"] * run["setting"].get("rate", 1.0)
        ckpt = basalt.read_checkpoint(run["output"]) if any(q.needs_checkpoint for q in self.a.quantities) else None
        return {q.spec: q.measure(cols, ckpt, self.a.window_start, self.t_end) for q in self.a.quantities}

    # ------------------------------------------------------------------------------------------- plan

    def prepare(self):
        os.makedirs(os.path.join(self.out, "geometry"), exist_ok=True)
        ident = {"scene": os.path.abspath(self.scene_path), "scene_sha": sha(self.scene_path),
                 "geometry_sha": sha(self.geometry), "steps": self.a.steps, "time": self.a.time, "np": self.a.np,
                 "rows": self.a.rows, "perturbation": self.a.perturbation,
                 "reference_dt_fraction": self.a.reference_dt_fraction}
        plan = os.path.join(self.out, "plan.json")
        if os.path.exists(plan):
            old = load_json(plan)
            changed = [k for k in ident if old.get(k) != ident[k]]
            if changed:
                raise StudyError(f"{self.out}: a study of another scene or window is in this folder "
                                 f"({', '.join(changed)} changed): give another --out, or remove the folder")
        rep.write_json(plan, ident)
        self.members = []
        for m in range(self.a.ensemble + 1):
            path = os.path.join(self.out, "geometry", f"member{m}.h5")
            if not os.path.exists(path):
                perturb.write_member(self.geometry, path + ".tmp.h5", m, self.a.perturbation)
                os.replace(path + ".tmp.h5", path)
            self.members.append(path)
        # The scene as it is, one step: its dt (the window's unit), fields' columns, checkpoint's datasets.
        own = {"precision": self.scene["run"].get("precision", "double"), "dt_fraction": None, "stiffness": 1.0,
               "skin": self.scene["run"].get("skin")}
        folder = os.path.join(self.out, "runs", "scene-probe")
        info, err = self.probe(folder, self.write_scene(folder, own, self.members[0]), own["precision"])
        if info is None:
            raise StudyError(f"{self.scene_path}: basalt-run refuses the scene: {err}")
        for q in self.a.quantities:
            q.check_fields(info["columns"])
        if any(q.needs_checkpoint for q in self.a.quantities):
            import basalt
            ckpt = basalt.read_checkpoint(info["checkpoint"])
            for q in self.a.quantities:
                q.check_checkpoint(ckpt)
        steps = self.a.steps if self.a.steps is not None else self.scene["run"].get("steps")
        if self.a.time is None and not steps:
            raise StudyError(f"{self.scene_path}: run.steps: missing or 0: give the window (--steps or --time)")
        self.t_end = self.a.time if self.a.time is not None else steps * info["dt"]
        if not 0 <= self.a.window_start < self.t_end:
            raise StudyError(f"--window-start: {self.a.window_start:g} is not inside the window [0, {self.t_end:g}]")
        scene_fraction = float(f"{info['dt'] / info['critical_step']:.3g}") if info.get("critical_step") else None
        fractions = self.a.dt_fraction or ([scene_fraction] if scene_fraction else None)
        if not fractions:
            raise StudyError(f"{self.scene_path}: the scene has no critical step to take a fraction of: give "
                             "--dt-fraction")
        skins = self.a.skin or [own["skin"]]
        base = {"precision": "double", "dt_fraction": self.a.reference_dt_fraction, "stiffness": 1.0,
                "skin": own["skin"], "rate": 1.0, "damping": 1.0}
        runs = [{"key": "reference", "kind": "reference", "setting": dict(base), "member": 0}]
        runs += [{"key": f"ensemble{m}", "kind": "ensemble", "setting": dict(base), "member": m}
                 for m in range(1, self.a.ensemble + 1)]
        for prec, frac, k, skin, rate, damp in itertools.product(
                self.a.precision or [own["precision"]], fractions, self.a.stiffness or [1.0], skins,
                self.a.rate or [1.0], self.a.damping or [1.0]):
            s = {"precision": prec, "dt_fraction": frac, "stiffness": k, "skin": skin, "rate": rate, "damping": damp}
            if s != base:
                key = f"{prec}-dtf{frac:g}-k{k:g}-skin{skin:g}"  # the keys of studies without the newer axes
                key += (f"-rate{rate:g}" if rate != 1 else "") + (f"-damp{damp:g}" if damp != 1 else "")
                runs.append({"key": key, "kind": "setting", "setting": s})
        if self.a.presets:
            for name in ("fast", "balanced", "reference"):
                s = dict(base, precision=None, dt_fraction=None, preset=name)
                runs.append({"key": f"preset-{name}", "kind": "setting", "setting": s})
        # A scene without contacts, moving walls or damping says so before any run.
        if any(r["setting"]["stiffness"] != 1 for r in runs):
            so.apply(self.scene, stiffness=0.5, scene_path=self.scene_path)
        if any(r["setting"]["rate"] != 1 for r in runs):
            so.apply(self.scene, rate=0.5, scene_path=self.scene_path)
        if any(r["setting"]["damping"] != 1 for r in runs):
            so.apply(self.scene, damping=0.5, scene_path=self.scene_path)
        for section in ("insert", "delete"):
            if self.scene.get(section):
                self.say(f"warning: {section}: its events count steps, so a setting with another dt has them at "
                         "other times")
        self.say(f"{self.scene_path}: {info['particles']} particles, window t = 0 .. {self.t_end:g} "
                 f"({steps or '-'} steps of the scene's dt = {info['dt']:.4g}); {len(runs)} runs into {self.out}")
        return runs

    def go(self):
        runs = self.prepare()
        self.spent, self.work_done, self.runs_timed = 0.0, 0, 0
        finished = []
        for k, run in enumerate(runs, 1):
            before = self.work_done
            if run["kind"] == "ensemble":
                # the reference's step: members differ by the nudge alone
                run.update(fixed_dt=finished[0]["dt"], particles=finished[0]["particles"])
            finished.append(self.run(run, k, len(runs)))
            self.runs_timed += self.work_done > before
            if run["kind"] == "reference" and finished[-1]["status"] != "ok":
                raise StudyError(f"the reference run failed: {finished[-1]['message']}")
        self.report(finished)

    def report(self, runs):
        specs = [q.spec for q in self.a.quantities]
        for r in runs:
            if r["status"] == "ok" and any(s not in r["quantities"] for s in specs):
                r["quantities"] = self.measure(r)
                rep.write_json(os.path.join(self.out, "runs", r["key"], "result.json"), r)
        ref, spreads = rep.evaluate(runs, specs)
        table_runs = [r for r in runs if r["kind"] in ("reference", "setting")]
        rep.pareto(table_runs)
        best = rep.cheapest(table_runs, self.a.budget) if self.a.budget is not None else None
        text = rep.markdown(runs, specs, spreads, ref, self.a.budget, best, cpu_name())
        with open(os.path.join(self.out, "table.md"), "w") as f:
            f.write(text)
        rep.write_json(os.path.join(self.out, "study.json"),
                       {"scene": os.path.abspath(self.scene_path), "window": [self.a.window_start, self.t_end],
                        "quantities": specs, "spread": spreads, "host": cpu_name(), "budget": self.a.budget,
                        "cheapest": best["key"] if best else None, "runs": runs}, strict=True)
        if not self.a.no_plot:
            rep.plot(runs, specs, spreads, ref, os.path.join(self.out, "study.png"))
        print(text)
        if best:
            with open(os.path.join(self.out, "setting.toml"), "w") as f:
                f.write(rep.fragment(best, self.scene, self.scene_path, self.a.budget))
            self.say(f"cheapest within --budget {self.a.budget:g}: {best['key']} "
                     f"({best['speedup']:.2f}x the reference's speed); {self.out}/setting.toml")
        elif self.a.budget is not None:
            self.say(f"no setting is within --budget {self.a.budget:g}")
        self.say(f"wrote {self.out}/table.md, study.json" + ("" if self.a.no_plot else ", study.png"))


def failure(p):
    """The first error line of a failed basalt-run (or its last line)."""
    text = (p.stderr or "") + "\n" + (p.stdout or "")
    lines = [x.strip() for x in text.splitlines() if x.strip() and not x.startswith(("Command ", "\t"))]
    for x in lines:
        if "error" in x.lower() or "blow-up" in x:
            return x[:300]
    return (lines[-1] if lines else f"exit status {p.returncode}")[:300]


def load_json(path):
    import json
    with open(path) as f:
        return json.load(f)


def fmt_s(s):
    return f"{s:.0f} s" if s < 120 else f"{s / 60:.1f} min"


def main(argv=None):
    try:
        a = parse_args(argv)
        check_args(a)
        Study(a).go()
    except (StudyError, qty.QuantityError, so.SceneError) as e:
        print(f"basalt-study: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("basalt-study: stopped; the finished runs are kept: the same command resumes", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
