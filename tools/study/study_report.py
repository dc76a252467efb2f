"""What a study reports: each setting's error against the reference and against the ensemble's spread, its
cost and speed relative to the reference, the Pareto front, the cheapest setting within a budget, and the
files: table.md, study.json, study.png, setting.toml.

Definitions (docs/accuracy.md, "Your own scene: basalt-study"):
  error      |q - q_ref| / |q_ref| per quantity (|q - q_ref| when q_ref = 0), and its largest over the quantities;
  spread     the largest |q_m - q_ref| over the perturbed references m: the scene's chaos floor for q;
  noise      |q - q_ref| / spread: <= 1 is "inside the noise", the setting is as good as the reference can tell;
  cost       CPU seconds of basalt-run's loop (times its ranks) per unit of simulated time;
  speed-up   the reference's cost over the setting's (measured in the same study, on the same machine).
A setting is within a budget E when every quantity's error is <= E or inside the noise.
"""
import json
import math
import os


def _spread(runs, spec, ref):
    members = [r["quantities"][spec] for r in runs if r["kind"] == "ensemble" and r["status"] == "ok"]
    return max((abs(v - ref) for v in members), default=float("nan"))


def evaluate(runs, specs):
    """Adds to each finished run (dicts of the study's result.json files) 'errors' {spec: relative error},
    'noise' {spec: error / spread}, 'max_error', 'cost', 'speedup'; returns (reference, spreads)."""
    ref = next(r for r in runs if r["kind"] == "reference")
    spreads = {s: _spread(runs, s, ref["quantities"][s]) for s in specs}
    for r in runs:
        if r["status"] != "ok":
            continue
        r["cost"] = r["cpu_s"] * r["ranks"] / r["sim_time"] if r["sim_time"] > 0 else float("nan")
        r["errors"], r["noise"] = {}, {}
        for s in specs:
            q, q0 = r["quantities"][s], ref["quantities"][s]
            d = abs(q - q0)
            r["errors"][s] = d / abs(q0) if q0 != 0 else d
            sp = spreads[s]
            r["noise"][s] = (d / sp) if sp > 0 else (0.0 if d == 0 else float("inf"))
        r["max_error"] = max(r["errors"].values()) if specs else 0.0
    for r in runs:
        if r["status"] == "ok":
            r["speedup"] = ref["cost"] / r["cost"] if r["cost"] > 0 else float("nan")
    return ref, spreads


def pareto(settings):
    """Marks r['pareto'] on the finished settings no other is both cheaper and more accurate than."""
    ok = [r for r in settings if r["status"] == "ok"]
    for r in ok:
        r["pareto"] = not any(o is not r and o["cost"] <= r["cost"] and o["max_error"] <= r["max_error"]
                              and (o["cost"] < r["cost"] or o["max_error"] < r["max_error"]) for o in ok)


def within(r, budget):
    return r["status"] == "ok" and all(r["errors"][s] <= budget or r["noise"][s] <= 1 for s in r["errors"])


def cheapest(settings, budget):
    """The finished setting of least cost within `budget`, or None."""
    fits = [r for r in settings if within(r, budget)]
    return min(fits, key=lambda r: r["cost"]) if fits else None


def _g(v):
    return "-" if v is None else f"{v:g}"


def label(r):
    s = r["setting"]
    text = f"{s['precision'] or '-'} dtf {_g(s['dt_fraction'])} k x{s['stiffness']:g} skin {s['skin']:g}"
    if s.get("preset"):
        text = f"preset {s['preset']} ({text})"
    for key, name in (("rate", "rate"), ("damping", "damping")):
        if s.get(key, 1.0) != 1:
            text += f" {name} x{s[key]:g}"
    return text


def _err(r, s):
    e, n = r["errors"][s], r["noise"][s]
    tag = "inside" if n <= 1 else (f"{n:.3g}x" if math.isfinite(n) else "> 0 spread")
    return f"{e:.2e} ({tag})"


def markdown(runs, specs, spreads, ref, budget=None, best=None, cpu=""):
    """The Pareto table as markdown text."""
    q_heads = " | ".join(f"`{s}`: error (x spread)" for s in specs)
    out = [f"Reference: {label(ref)}; values " + ", ".join(f"`{s}` = {ref['quantities'][s]:.6g}" for s in specs)
           + ".", "Ensemble spread (chaos floor, relative): " +
           ", ".join(f"`{s}` {spreads[s] / abs(ref['quantities'][s]) if ref['quantities'][s] else spreads[s]:.2e}"
                     for s in specs) + ".", ""]
    if cpu:
        out += [f"Host: {cpu}. Speed-up: the reference's CPU seconds per simulated time unit over the setting's, "
                "both measured in this study.", ""]
    # Loading-rate and damping columns only in studies that vary them.
    extra = [k for k in ("rate", "damping") if any(r["setting"].get(k, 1.0) != 1 for r in runs)]
    out.append(f"| run | precision | dt fraction | stiffness | skin |{''.join(f' {k} |' for k in extra)} dt | steps | "
               f"{q_heads} | max error | speed-up | simulated time per CPU s | M particle-steps/s | RSS B/particle | "
               "Pareto |")
    out.append("|" + " --- |" * (13 + len(extra) + len(specs)))
    for r in runs:
        s = r["setting"]
        head = (f"| {r['key']} | {s['precision'] or '-'} | {_g(s['dt_fraction'])} | {s['stiffness']:g} | {s['skin']:g} |"
                + "".join(f" {s.get(k, 1.0):g} |" for k in extra))
        if r["status"] != "ok":
            msg = r["message"] if len(r["message"]) <= 110 else r["message"][:107] + "..."
            out.append(head + f" | | {msg.replace('|', '/')} |" + " |" * (len(specs) + 5))
            continue
        errs = " | ".join(_err(r, q) for q in specs)
        mark = "yes" if r.get("pareto") else ""
        if best is r:
            mark += " **cheapest within budget**"
        out.append(head + f" {r['dt']:.4g} | {r['steps']} | {errs} | {r['max_error']:.2e} | {r['speedup']:.2f} | "
                   f"{r['sim_time_per_cpu_s']:.3g} | {r['particle_steps_per_s'] / 1e6:.2f} | "
                   f"{r['rss_bytes_per_particle']:.0f} | {mark} |")
    if budget is not None:
        out += ["", f"Budget {budget:g}: " + (f"the cheapest setting within it is **{best['key']}** ({label(best)}), "
                                              f"{best['speedup']:.2f}x the reference's speed." if best else
                                              "no setting is within it.")]
    return "\n".join(out) + "\n"


def fragment(best, scene, scene_path, budget):
    """TOML lines the user can paste into the scene for setting `best`."""
    import scene_overrides as so
    s = best["setting"]
    lines = [f"# basalt-study of {scene_path}: the cheapest setting within --budget {budget:g}"
             + (f" (basalt-run --preset {s['preset']} does the same)" if s.get("preset") else ""),
             f"# (every error within it or inside the ensemble's spread; largest {best['max_error']:.2e}; "
             f"{best['speedup']:.2f}x the reference's speed). Paste into the scene:", "[run]", f'precision = "{s["precision"]}"',
             f"dt_fraction = {s['dt_fraction']!r}   # replaces run.dt", f"skin = {s['skin']!r}"]
    if s["stiffness"] != 1:
        lines.append(f"# contact stiffness x {s['stiffness']:g}: set these keys")
        scaled = so.apply(scene, stiffness=s["stiffness"])
        for where, table, key in so.stiffness_keys(scaled):
            lines.append(f"#   {where}: {key} = {table[key]!r}")
    if s.get("rate", 1.0) != 1:
        lines.append(f"# loading rate x {s['rate']:g}: these wall motions (and run.steps / {s['rate']:g})")
        scaled = so.apply(scene, rate=s["rate"])
        for section in ("walls", "mesh_walls"):
            for w in scaled.get(section, []):
                if w.get("motion", {}).get("type", "fixed") not in ("fixed", "servo"):
                    lines.append(f"#   {section} \"{w.get('name', '')}\": motion = {so._value(w['motion'])}")
    if s.get("damping", 1.0) != 1:
        lines.append(f"# damping x {s['damping']:g}: set these keys")
        scaled = so.apply(scene, damping=s["damping"])
        for k, b in enumerate(scaled.get("body_forces", [])):
            key = so.DAMPING_KEYS.get(b.get("type"))
            if key and key in b:
                lines.append(f"#   body_forces[{k}] \"{b['type']}\": {key} = {b[key]!r}")
    return "\n".join(lines) + "\n"


def plot(runs, specs, spreads, ref, path):
    """study.png: per quantity, relative error against speed-up; colour the stiffness scale, marker the precision,
    size the dt fraction; the ensemble's spread as a grey band (below it: inside the noise)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ok = [r for r in runs if r["status"] == "ok" and r["kind"] == "setting"]
    stiff = sorted({r["setting"]["stiffness"] for r in ok}, reverse=True) or [1.0]
    fracs = sorted({r["setting"]["dt_fraction"] for r in ok}) or [1.0]
    colour = {k: plt.get_cmap("tab10")(i % 10) for i, k in enumerate(stiff)}
    size = {f: 18 + 60 * i / max(1, len(fracs) - 1) for i, f in enumerate(fracs)}
    markers = {"double": "o", "float": "s", "mixed": "^"}
    n = max(1, len(specs))
    cols = min(2, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(6.2 * cols, 4.4 * rows), squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    for ax, s in zip(axes.flat, specs):
        q0 = ref["quantities"][s]
        rel_spread = spreads[s] / abs(q0) if q0 else spreads[s]
        errs = [r["errors"][s] for r in ok if r["errors"][s] > 0] + ([rel_spread] if rel_spread > 0 else [])
        low = min(errs) / 3 if errs else 1e-12
        for r in ok:
            st = r["setting"]
            ax.scatter(r["speedup"], max(r["errors"][s], low), marker=markers.get(st["precision"], "x"),
                       color=colour[st["stiffness"]], edgecolors="k", linewidths=0.4, s=size[st["dt_fraction"]])
            tag = " ".join(t for t in (st.get("preset") or "",
                                        f"rate x{st['rate']:g}" if st.get("rate", 1.0) != 1 else "",
                                        f"damping x{st['damping']:g}" if st.get("damping", 1.0) != 1 else "") if t)
            if tag:  # the axes the markers do not show
                ax.annotate(tag, (r["speedup"], max(r["errors"][s], low)), fontsize=6, xytext=(3, 3),
                            textcoords="offset points")
        if rel_spread > 0:
            ax.axhspan(low, rel_spread, color="0.88", zorder=0)
            ax.axhline(rel_spread, color="0.5", lw=0.8, zorder=0)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(bottom=low)
        ax.set_xlabel("speed-up against the reference (CPU time per simulated time)")
        ax.set_ylabel("relative error")
        ax.set_title(s, fontsize=9)
    first = axes.flat[0]
    first.fill_between([], [], color="0.88", label="inside the ensemble spread")
    for k in stiff:
        first.scatter([], [], color=colour[k], label=f"stiffness x {k:g}")
    for p, m in markers.items():
        if any(r["setting"]["precision"] == p for r in ok):
            first.scatter([], [], marker=m, color="w", edgecolors="k", label=p)
    first.scatter([], [], marker="o", color="w", edgecolors="k", s=size[fracs[0]], label=f"dt fraction {fracs[0]:g}")
    first.scatter([], [], marker="o", color="w", edgecolors="k", s=size[fracs[-1]], label=f"dt fraction {fracs[-1]:g}")
    first.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _finite(v):
    """v with every non-finite float replaced by None (strict JSON)."""
    if isinstance(v, float) and not math.isfinite(v):
        return None
    if isinstance(v, dict):
        return {k: _finite(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_finite(x) for x in v]
    return v


def write_json(path, payload, strict=False):
    """Writes `payload` to `path` atomically (a temporary name, then renamed); strict: non-finite numbers as null
    (the study's summary, read by other programs), else as NaN/Infinity (a run's result.json, read back here)."""
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(_finite(payload) if strict else payload, f, indent=1, allow_nan=not strict)
    os.replace(tmp, path)
