"""A scene as a dict, a setting's overrides applied to it, and the result written back as TOML.

basalt-run has no generic override option (only --precision, --steps, --output ...), so a setting of a study
is a scene file of its own, written into the study's folder: the user's scene read with tomllib, changed in
the keys the setting names, written by `dumps` (the scene's comments are not kept; its keys and values are).

Overrides (docs/accuracy.md, "Your own scene: basalt-study"):
  * dt_fraction: run.dt_fraction (run.dt removed); the step follows the critical step of the scene as set;
  * stiffness:   every contact stiffness times the scale: K and Ks of linear_elastic, friction, rot_friction,
                 rolling_friction, test_contact_age groups and of elastic and friction walls and mesh walls;
                 E of hertz_mindlin and jkr groups, E and E_wall of hertz_mindlin walls. Bonds (linear_bond,
                 rot_bond, bonded walls) are not contacts and are left alone;
  * skin:        run.skin.
  * rate:        the loading rate times the scale: every prescribed wall motion runs S times faster (velocities,
                 amplitudes and angular velocities x S; periods, ramp times and start times / S), so the same
                 displacements are reached in 1/S of the time; servo walls and fixed walls are left alone (a
                 scene whose walls prescribe no motion has nothing to scale and is refused).
  * damping:     every body-force damping times the scale: viscosity of linear_damping and rotational_damping,
                 alpha of local_damping (alpha x S must stay below 1).
Paths (geometry.file, mesh_walls[k].file) are made absolute, since the written scene lives elsewhere.
"""
import copy
import json
import math
import os
import tomllib


class SceneError(ValueError):
    """A scene the study cannot use; the message names the file and the key."""


# Contact stiffness keys by model; bonds are not contacts.
CONTACT_KEYS = {"linear_elastic": ("K",), "friction": ("K", "Ks"), "rot_friction": ("K", "Ks"),
                "rolling_friction": ("K", "Ks"), "test_contact_age": ("K",), "hertz_mindlin": ("E",),
                "jkr": ("E",)}
WALL_KEYS = {"elastic": ("K",), "friction": ("K", "Ks"), "hertz_mindlin": ("E", "E_wall")}


def load(path):
    """The scene `path` as a dict (tomllib); SceneError naming the file when it cannot be read."""
    try:
        with open(path, "rb") as f:
            scene = tomllib.load(f)
    except OSError as e:
        raise SceneError(f"{path}: cannot read the scene: {e.strerror}")
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{path}: not a TOML file: {e}")
    if "run" not in scene:
        raise SceneError(f"{path}: run: missing table (docs/scenes.md)")
    if scene.get("stages"):
        raise SceneError(f"{path}: stages: a staged scene is not supported yet by basalt-study (its stages count "
                         "steps, which differ between settings); study one stage as a scene of its own")
    return scene


def absolute_paths(scene, scene_path, geometry=None):
    """A copy of `scene` whose file paths are absolute (relative ones being relative to the scene's folder);
    `geometry` (relative to the current folder) replaces geometry.file when given."""
    s = copy.deepcopy(scene)
    base = os.path.dirname(os.path.abspath(scene_path))
    s.setdefault("geometry", {})
    if geometry:
        s["geometry"]["file"] = os.path.abspath(geometry)
    elif "file" not in s["geometry"]:
        raise SceneError(f"{scene_path}: geometry.file: missing (or give --geometry)")
    else:
        s["geometry"]["file"] = os.path.join(base, s["geometry"]["file"])
    for m in s.get("mesh_walls", []):
        if "file" in m:
            m["file"] = os.path.join(base, m["file"])
    return s


def stiffness_keys(scene):
    """[(where, table, key)] of every contact stiffness of the scene: where is e.g. 'interactions "grains"'."""
    found = []
    for k, g in enumerate(scene.get("interactions", [])):
        for key in CONTACT_KEYS.get(g.get("type"), ()):
            if key in g:
                found.append((f'interactions[{k}] "{g.get("name", g.get("type"))}"', g, key))
    for section in ("walls", "mesh_walls"):
        for k, w in enumerate(scene.get(section, [])):
            for key in WALL_KEYS.get(w.get("interaction", "elastic"), ()):
                if key in w:
                    found.append((f'{section}[{k}] "{w.get("name", section + str(k))}"', w, key))
    return found


RATE_TIMES = ("period", "ramp_time", "start_time")
RATE_SPEEDS = ("velocity", "amplitude")
DAMPING_KEYS = {"linear_damping": "viscosity", "rotational_damping": "viscosity", "local_damping": "alpha"}


def _scaled(v, f):
    return [x * f for x in v] if isinstance(v, list) else v * f


def scale_rate(scene, rate, scene_path="scene"):
    """Every prescribed wall motion of `scene` (changed in place) S = `rate` times faster."""
    moving = 0
    for section in ("walls", "mesh_walls"):
        for w in scene.get(section, []):
            m = w.get("motion")
            if not m or m.get("type", "fixed") in ("fixed", "servo"):
                continue
            moving += 1
            for key in RATE_SPEEDS:
                if key in m:
                    m[key] = _scaled(m[key], rate)
            for key in RATE_TIMES:
                if key in m:
                    m[key] = m[key] / rate
            if "rotation" in m and "angular_velocity" in m["rotation"]:
                m["rotation"]["angular_velocity"] *= rate
    if not moving:
        raise SceneError(f"{scene_path}: walls: no wall with a prescribed motion (constant_velocity, ramp, sine, "
                         "half_sine): a loading-rate scale has nothing to scale")


def scale_damping(scene, factor, scene_path="scene"):
    """Every body-force damping of `scene` (changed in place) times `factor`."""
    found = 0
    for k, b in enumerate(scene.get("body_forces", [])):
        key = DAMPING_KEYS.get(b.get("type"))
        if key and key in b:
            b[key] = b[key] * factor
            found += 1
            if key == "alpha" and not b[key] < 1:
                raise SceneError(f"{scene_path}: body_forces[{k}].alpha x {factor:g} = {b[key]:g}: local damping "
                                 "needs alpha < 1")
    if not found:
        raise SceneError(f"{scene_path}: body_forces: no damping ({', '.join(DAMPING_KEYS)}): a damping scale has "
                         "nothing to scale")


def apply(scene, dt_fraction=None, stiffness=None, skin=None, scene_path="scene", dt=None, rate=None,
          damping=None):
    """A copy of `scene` with the setting's overrides (None: the scene's own value); `dt`, a fixed step, wins
    over dt_fraction."""
    s = copy.deepcopy(scene)
    if rate is not None and rate != 1:
        scale_rate(s, float(rate), scene_path)
    if damping is not None and damping != 1:
        scale_damping(s, float(damping), scene_path)
    run = s["run"]
    if dt is not None:
        run.pop("dt_fraction", None)
        run["dt"] = float(dt)
    elif dt_fraction is not None:
        run.pop("dt", None)
        run["dt_fraction"] = float(dt_fraction)
    if skin is not None:
        run["skin"] = float(skin)
    if stiffness is not None and stiffness != 1:
        keys = stiffness_keys(s)
        if not keys:
            raise SceneError(f"{scene_path}: interactions: no contact model (one of {', '.join(CONTACT_KEYS)}) "
                             "and no contact wall: a contact-stiffness scale has nothing to scale")
        for _, table, key in keys:
            table[key] = table[key] * float(stiffness)
    return s


# ------------------------------------------------------------------------------------------------- TOML


def _value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise SceneError(f"cannot write a {type(v).__name__} to TOML: {v!r}")


def _key(k):
    return k if k.replace("_", "").replace("-", "").isalnum() else json.dumps(k)


def _is_tables(v):
    return isinstance(v, list) and v and all(isinstance(x, dict) for x in v)


def _table(lines, prefix, table):
    for k, v in table.items():
        if not isinstance(v, dict) and not _is_tables(v):
            lines.append(f"{_key(k)} = {_value(v)}")
    for k, v in table.items():
        name = f"{prefix}.{_key(k)}" if prefix else _key(k)
        if isinstance(v, dict):
            lines += ["", f"[{name}]"]
            _table(lines, name, v)
        elif _is_tables(v):
            for item in v:
                lines += ["", f"[[{name}]]"]
                _table(lines, name, item)


def dumps(scene):
    """TOML text of a scene dict (tables, arrays of tables, inline tables nested in values)."""
    lines = []
    _table(lines, "", scene)
    return "\n".join(lines).lstrip("\n") + "\n"
