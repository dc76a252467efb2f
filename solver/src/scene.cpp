#include "basalt/solver/scene/scene.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "basalt/io/mesh_file.hpp"
#include "basalt/io/render_options.hpp"
#include "basalt/solver/models/registry.hpp"
#include "basalt/solver/stages.hpp"

namespace basalt::solver {

namespace fs = std::filesystem;

namespace {

std::array<double, 3> unit(TableReader& t, const std::string& key) {
  auto v = t.vec3(key);
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(n > 0)) t.fail(key, "must have non-zero length");
  return {v[0] / n, v[1] / n, v[2] / n};
}

TagFilter pair_tags(TableReader& t) {
  auto tags = t.integers_or("tags", {});
  if (!tags.empty() && tags.size() != 2) t.fail("tags", "must name two particle tags, e.g. [0, 0]");
  return tags;
}

std::string group_name(TableReader& t, const std::string& fallback, std::set<std::string>& seen) {
  std::string name = t.string_or("name", fallback);
  if (name.empty()) t.fail("name", "must not be empty");
  if (!seen.insert(name).second) t.fail("name", fmt::format("\"{}\" is used twice", name));
  return name;
}

/// One [[mesh_walls]] table: the mesh read and placed (scale, then offset), its model, sides, tags, motion.
MeshWallSpec parse_mesh_wall(TableReader& t, const std::string& label, const std::string& path,
                             const fs::path& base_dir) {
  MeshWallSpec w;
  fs::path file = t.string("file");
  if (file.empty())
    t.fail("file", "is empty: name the mesh file (.stl, .obj or .off), relative to the scene's folder");
  w.file = file.is_absolute() ? file : base_dir / file;
  io::MeshReadOptions opt;
  opt.weld_tolerance = t.non_negative_or("weld_tolerance", 0);
  io::TriangleMesh m;
  try {
    m = io::read_mesh(w.file, opt);
  } catch (const std::exception& e) {
    t.fail("file", e.what());
  }
  const double scale = t.has("scale") ? t.positive("scale") : 1.0;
  const auto offset = t.vec3_opt("offset").value_or(std::array<double, 3>{0, 0, 0});
  for (auto& v : m.vertices)
    for (int d = 0; d < 3; ++d) v[d] = v[d] * scale + offset[d];
  w.vertices = std::move(m.vertices);
  w.triangles = std::move(m.triangles);
  w.one_sided = t.choice_or("sides", {"two", "one"}, "two") == "one";
  w.model = t.choice_or("interaction", model_names(ModelKind::wall), "elastic");
  if (!find_model(w.model, ModelKind::wall)->make_mesh_double)
    t.fail("interaction", fmt::format("\"{}\" is for planar [[walls]] only", w.model));
  w.params = find_model(w.model, ModelKind::wall)->parse(t);
  w.tags = t.integers_or("tags", {});
  if (const auto* mt = t.subtable("motion")) {
    TableReader tm(*mt, label, path + ".motion");
    if (const auto* rt = tm.subtable("rotation")) {
      TableReader tr(*rt, label, path + ".motion.rotation");
      w.axis = unit(tr, "axis");
      w.axis_point = tr.vec3_opt("point").value_or(std::array<double, 3>{0, 0, 0});
      w.angular_velocity = tr.number("angular_velocity");
      if (!std::isfinite(w.angular_velocity)) tr.fail("angular_velocity", "must be finite");
      tr.finish();
    }
    // A mesh has no normal to move along by default: sine motions name their direction.
    const std::string type = tm.has("type") ? tm.string("type") : "fixed";
    if ((type == "sine" || type == "half_sine") && !tm.has("direction"))
      tm.fail("direction", fmt::format("missing (required for a mesh wall's \"{}\" motion)", type));
    if (type == "servo")
      tm.fail("type",
              "\"servo\" is for planar [[walls]] only (a mesh wall has no normal to hold a force along)");
    w.motion = parse_motion(tm, {0, 0, 1});
  }
  t.finish();
  return w;
}

std::string scene_too_large(const std::string& label, std::uintmax_t bytes) {
  return fmt::format(
      "{}: the scene is {:.1f} MB, more than the {} MB a scene may have (its text is stored in every "
      "checkpoint); keep particles and tables in the geometry file",
      label, double(bytes) * 1e-6, kMaxSceneBytes / 1000000);
}

}  // namespace

WallMotion parse_motion(TableReader& t, const std::array<double, 3>& normal) {
  WallMotion m;
  const std::string type =
      t.choice_or("type", {"fixed", "constant_velocity", "half_sine", "sine", "ramp", "servo"}, "fixed");
  if (type == "fixed") {
    m.type = WallMotion::Type::fixed;
  } else if (type == "constant_velocity") {
    m.type = WallMotion::Type::constant_velocity;
    m.velocity = t.vec3("velocity");
  } else if (type == "ramp") {
    m.type = WallMotion::Type::ramp;
    m.velocity = t.vec3("velocity");
    m.ramp_time = t.non_negative("ramp_time");
    m.start_time = t.number_or("start_time", 0.0);
    // A negative t0 (at most ramp_time before the start) puts the run's start inside the ramp: ESyS's
    // WallLoaderRunnable, a pre-time-step runnable, is matched by t0 = -dt/2 (docs/scenes.md).
    if (!std::isfinite(m.start_time) || m.start_time < -m.ramp_time)
      t.fail("start_time", "must be finite and >= -ramp_time");
  } else if (type == "servo") {
    m.type = WallMotion::Type::servo;
    const bool force = t.has("target_force"), stress = t.has("target_stress");
    if (force == stress)
      t.fail(force ? "target_stress" : "target_force",
             force ? "give target_force or target_stress (with area), not both"
                   : "missing: a servo wall needs target_force, or target_stress and area");
    if (force) {
      m.servo.target_force = t.number("target_force");
      if (!std::isfinite(m.servo.target_force)) t.fail("target_force", "must be finite");
      if (t.has("area")) t.fail("area", "only with target_stress (target_force is already a force)");
    } else {
      const double sigma = t.number("target_stress");
      if (!std::isfinite(sigma)) t.fail("target_stress", "must be finite");
      m.servo.target_force = sigma * t.positive("area");
    }
    m.servo.gain = t.positive("gain");
    m.servo.max_speed = t.positive("max_speed");
  } else {
    m.type = type == "half_sine" ? WallMotion::Type::half_sine : WallMotion::Type::sine;
    m.amplitude = t.number("amplitude");
    if (!std::isfinite(m.amplitude)) t.fail("amplitude", "must be finite");
    m.period = t.positive("period");
    m.direction = t.has("direction") ? unit(t, "direction") : normal;
  }
  t.finish();
  return m;
}

Scene parse_scene_text(const std::string& text, const std::string& label, const fs::path& base_dir) {
  if (text.size() > kMaxSceneBytes) throw InputError(scene_too_large(label, text.size()));
  toml::table root;
  try {
    root = toml::parse(text, label);
  } catch (const toml::parse_error& e) {
    throw InputError(
        fmt::format("{}:{}:{}: {}", label, e.source().begin.line, e.source().begin.column, e.description()));
  }
  Scene s;
  s.text = text;
  TableReader top(root, label, "");

  if (const auto* u = top.subtable("units")) {
    TableReader t(*u, label, "units");
    s.units.length = t.choice_or("length", {"mm", "m"}, "mm");
    s.units.time = t.choice_or("time", {"ms", "s"}, "ms");
    s.units.force = t.choice_or("force", {"N", "kN"}, "N");
    t.finish();
  }

  {
    const auto* g = top.subtable("geometry");
    if (!g) top.fail("geometry", "missing (required): a [geometry] table with file = \"...\"");
    TableReader t(*g, label, "geometry");
    fs::path p = t.string("file");
    // An empty path would resolve to the scene's folder and be refused as "a folder, not a file".
    if (p.empty())
      t.fail("file", "is empty: name the geometry file (.h5 or .geo), relative to the scene's folder");
    s.geometry = p.is_absolute() ? p : base_dir / p;
    t.finish();
  }

  if (const auto* m = top.subtable("material")) {
    TableReader t(*m, label, "material");
    if (t.has("density")) s.density = t.positive("density");
    t.finish();
  }

  std::optional<bool> rotation, orientation;
  if (const auto* m = top.subtable("particles")) {
    TableReader t(*m, label, "particles");
    if (t.has("rotation")) rotation = t.boolean_or("rotation", false);
    if (t.has("orientation")) orientation = t.boolean_or("orientation", false);
    s.fixed_tags = t.integers_or("fixed_tags", {});
    t.finish();
  }

  {
    const auto* r = top.subtable("run");
    if (!r) top.fail("run", "missing (required): a [run] table with dt, steps, skin");
    TableReader t(*r, label, "run");
    if (t.has("dt") && t.has("dt_fraction"))
      t.fail("dt_fraction",
             "run.dt and run.dt_fraction are both given: choose one (run.dt an absolute step, "
             "run.dt_fraction a fraction of the critical step)");
    if (t.has("dt_fraction")) {
      s.dt_fraction = t.positive("dt_fraction");  // dt is set by the simulation (simulation_stability.cpp)
    } else if (t.has("dt")) {
      s.dt = t.positive("dt");
    } else {
      t.fail_here(
          "missing run.dt or run.dt_fraction (one is required): the time step, absolute or as a "
          "fraction of the critical step");
    }
    s.precision = t.choice_or("precision", {"double", "float", "mixed"}, "double");
    // With [[stages]] each stage's steps say how long it runs: run.steps may be left out (or 0).
    s.steps = top.has("stages") ? t.integer_or("steps", 0) : t.integer("steps");
    if (s.steps < 0) t.fail("steps", fmt::format("must be >= 0, got {}", s.steps));
    if (s.steps > 0 && top.has("stages"))
      t.fail("steps",
             "the scene has [[stages]], whose steps = N say how long each runs: leave run.steps out");
    s.skin = t.positive("skin");
    s.integrator = t.choice_or("integrator", {"velocity_verlet", "symplectic_euler"}, "velocity_verlet") ==
                           "symplectic_euler"
                       ? Integrator::symplectic_euler
                       : Integrator::velocity_verlet;
    s.force_dt = t.boolean_or("force_dt", false);
    s.force_overlap = t.boolean_or("force_overlap", false);
    if (t.has("dt_safety")) {
      s.dt_safety = t.positive("dt_safety");
      if (s.dt_safety > 1) t.fail("dt_safety", "must be <= 1 (a fraction of the critical time step)");
    }
    s.energy_check_every = t.integer_or("energy_check_every", 100);
    if (s.energy_check_every < 0) t.fail("energy_check_every", "must be >= 0 (0 turns the guard off)");
    s.balance = t.choice_or("balance", {"none", "count", "pairs", "time"}, "none");
    if (t.has("balance_threshold")) {
      s.balance_threshold = t.positive("balance_threshold");
      if (s.balance_threshold < 1)
        t.fail("balance_threshold",
               "must be >= 1 (the busiest rank's particles or compute time over the mean, e.g. 1.2)");
    }
    s.balance_every = t.integer_or("balance_every", 500);
    if (s.balance_every < 1)
      t.fail("balance_every", "must be >= 1 (steps between checks of the compute times)");
    t.finish();
  }

  std::set<std::string> names;
  if (const auto* arr = top.table_array("interactions")) {
    for (std::size_t k = 0; k < arr->size(); ++k) {
      TableReader t(*(*arr)[k].as_table(), label, fmt::format("interactions[{}]", k));
      auto types = model_names(ModelKind::bond);
      for (auto& n : model_names(ModelKind::pair)) types.push_back(n);
      const std::string type = t.choice_or("type", types, "");
      const ModelEntry* m = find_model(type, ModelKind::bond);
      if (!m) m = find_model(type, ModelKind::pair);
      InteractionSpec g;
      g.model = type;
      g.kind = m->kind;
      const bool bond = m->kind == ModelKind::bond;
      g.name = group_name(t, fmt::format("{}{}", bond ? "bonds" : "contacts", k), names);
      g.params = m->parse(t);
      g.tags = pair_tags(t);
      if (bond && t.has("bond_tag")) g.bond_tag = t.integer("bond_tag");
      (bond ? s.bonds : s.contacts).push_back(std::move(g));
      t.finish();
    }
  }

  // Rotation: on when a model needs it, unless the scene turned it off (then that model is refused).
  {
    const InteractionSpec* needs = nullptr;
    for (const auto* list : {&s.bonds, &s.contacts})
      for (const auto& g : *list) {
        const ModelEntry* m = find_model(g.model, g.kind);
        if (m && (m->reads & (kAngularVelocity | kOrientation)) && !needs) needs = &g;
      }
    if (needs && rotation == false)
      throw InputError(
          fmt::format("{}: particles.rotation = false, but interaction \"{}\" (type \"{}\") needs rotating "
                      "particles: set "
                      "particles.rotation = true or choose a non-rotating model",
                      label, needs->name, needs->model));
    s.rotation = rotation.value_or(needs != nullptr);
    // Orientations: kept when a model reads them (a sphere's own motion never does) or the scene asks.
    const InteractionSpec* reads = nullptr;
    for (const auto* list : {&s.bonds, &s.contacts})
      for (const auto& g : *list) {
        const ModelEntry* m = find_model(g.model, g.kind);
        if (m && (m->reads & kOrientation) && !reads) reads = &g;
      }
    if (reads && orientation == false)
      throw InputError(fmt::format(
          "{}: particles.orientation = false, but interaction \"{}\" (type \"{}\") reads the particles' "
          "orientations: set particles.orientation = true or leave it out",
          label, reads->name, reads->model));
    if (orientation == true && !s.rotation)
      throw InputError(
          fmt::format("{}: particles.orientation = true needs rotating particles: set "
                      "particles.rotation = true (or leave orientation out)",
                      label));
    s.orientation = orientation.value_or(reads != nullptr);
  }

  if (const auto* arr = top.table_array("walls")) {
    for (std::size_t k = 0; k < arr->size(); ++k) {
      TableReader t(*(*arr)[k].as_table(), label, fmt::format("walls[{}]", k));
      WallSpec w;
      w.name = group_name(t, fmt::format("wall{}", k), names);
      w.point = t.vec3("point");
      w.normal = unit(t, "normal");
      w.model = t.choice_or("interaction", model_names(ModelKind::wall), "elastic");
      w.params = find_model(w.model, ModelKind::wall)->parse(t);
      w.tags = t.integers_or("tags", {});
      // The bonded wall's particles (its model's key, read here: the walls' candidates need them).
      if (w.model == "bonded") {
        w.bond_tags = t.integers_or("bond_tags", {});
        if (w.bond_tags.empty())
          t.fail("bond_tags", "missing: the tags of the particles tied to the wall, e.g. [2]");
      }
      if (const auto* m = t.subtable("motion")) {
        TableReader tm(*m, label, fmt::format("walls[{}].motion", k));
        w.motion = parse_motion(tm, w.normal);
      }
      // A wall the run adds later (a stage's add_walls, Python's walls[name].add()): moves, touches nothing.
      w.removed = !t.boolean_or("active", true);
      t.finish();
      s.walls.push_back(std::move(w));
    }
  }

  if (const auto* arr = top.table_array("mesh_walls")) {
    for (std::size_t k = 0; k < arr->size(); ++k) {
      const auto path = fmt::format("mesh_walls[{}]", k);
      TableReader t(*(*arr)[k].as_table(), label, path);
      const auto name = group_name(t, fmt::format("mesh{}", k), names);
      s.mesh_walls.push_back(parse_mesh_wall(t, label, path, base_dir));
      s.mesh_walls.back().name = name;
    }
  }

  if (const auto* arr = top.table_array("body_forces")) {
    for (std::size_t k = 0; k < arr->size(); ++k) {
      TableReader t(*(*arr)[k].as_table(), label, fmt::format("body_forces[{}]", k));
      InteractionSpec b;
      b.model = t.choice_or("type", model_names(ModelKind::body), "");
      b.kind = ModelKind::body;
      b.name = group_name(t, fmt::format("{}{}", b.model, k), names);
      const ModelEntry* m = find_model(b.model, ModelKind::body);
      b.params = m->parse(t);
      b.tags = t.integers_or("tags", {});
      // (without rotation the angular velocities are absent: ESyS's iterated form would divide by a zero
      // moment of inertia and put NaN in the ledger)
      if ((m->reads & kAngularVelocity) && !s.rotation)
        t.fail("type", fmt::format("\"{}\" acts on rotating particles, but the particles do not rotate: set "
                                   "particles.rotation = true, or remove it",
                                   b.model));
      t.finish();
      s.body_forces.push_back(std::move(b));
    }
  }

  if (const auto* o = top.subtable("output")) {
    TableReader t(*o, label, "output");
    if (t.has("directory")) {
      fs::path d = t.string("directory");
      // An empty path cannot be created ("Invalid argument"); leave the key out for the default "out".
      if (d.empty())
        t.fail("directory",
               "is empty: name the output folder (relative to the scene's folder), or leave the key out for "
               "\"out\"");
      s.output_dir = d.is_absolute() ? d : base_dir / d;
    }
    s.checkpoint_every = t.integer_or("checkpoint_every", 0);
    if (s.checkpoint_every < 0)
      t.fail("checkpoint_every", fmt::format("must be >= 0 (0 = off), got {}", s.checkpoint_every));
    s.frames_every = t.integer_or("frames_every", 0);
    if (s.frames_every < 0)
      t.fail("frames_every", fmt::format("must be >= 0 (0 = off), got {}", s.frames_every));
    s.output_continue_on_error = t.choice_or("on_error", {"stop", "continue"}, "stop") == "continue";
    // Obsolete since every checkpoint is a bit-for-bit restart point at no cost (a restart replays
    // the last rebuild); still accepted so that older scene files load.
    (void)t.boolean_or("exact_restart", true);
    // Checkpoint compression: checked here, applied by the I/O layer, which reads it from the scene text.
    (void)t.choice_or("compression", {"none", "fast", "small"}, "none");
    s.render_every = t.integer_or("render_every", 0);
    if (s.render_every < 0)
      t.fail("render_every", fmt::format("must be >= 0 (0 = off), got {}", s.render_every));
    s.render = t.string_or("render", "");
    try {
      (void)io::parse_render_spec(s.render, "output.render");
    } catch (const std::invalid_argument& e) {
      std::string what = e.what();  // "output.render cut ...": fail() names output.render itself
      if (what.rfind("output.render ", 0) == 0) what.erase(0, 14);
      t.fail("render", what);
    }
    s.frames_in_flight = t.integer_or("frames_in_flight", 2);
    if (s.frames_in_flight < 1)
      t.fail("frames_in_flight", fmt::format("must be >= 1, got {}", s.frames_in_flight));
    if (const auto* arr = t.table_array("fields")) {
      for (std::size_t k = 0; k < arr->size(); ++k) {
        TableReader tf(*(*arr)[k].as_table(), label, fmt::format("output.fields[{}]", k));
        // An energy term of the ledger (those every scene has, and the body forces'), or another saver.
        std::vector<std::string> allowed = standard_energy_terms();
        for (const auto& m : model_registry())
          for (const auto term : {m.energy_term, m.dissipation_term})
            if (!term.empty() && std::find(allowed.begin(), allowed.end(), term) == allowed.end())
              allowed.emplace_back(term);
        static const std::vector<std::pair<std::string, FieldSpec::Type>> kOther{
            {"total_energy", FieldSpec::Type::total_energy},
            {"bond_count", FieldSpec::Type::bond_count},
            {"wall_force", FieldSpec::Type::wall_force},
            {"wall_position", FieldSpec::Type::wall_position},
            {"rotational_kinetic_energy", FieldSpec::Type::rotational_kinetic_energy},
            {"sliding_contacts", FieldSpec::Type::sliding_contacts},
            {"runout", FieldSpec::Type::runout},
            {"mass_below", FieldSpec::Type::mass_below},
            {"mean_vz_above", FieldSpec::Type::mean_vz_above},
            {"broken_bonds", FieldSpec::Type::broken_bonds}};
        for (const auto& kind : kOther) allowed.push_back(kind.first);
        FieldSpec f;
        const std::string type = tf.choice_or("type", allowed, "");
        f.type = FieldSpec::Type::energy;
        for (const auto& kind : kOther)
          if (kind.first == type) f.type = kind.second;
        if (f.type == FieldSpec::Type::runout) {
          if (tf.has("origin")) f.origin = tf.vec3("origin");
          if (tf.has("direction")) f.direction = unit(tf, "direction");
          f.percentile = tf.number_or("percentile", 100);
          if (!(f.percentile > 0 && f.percentile <= 100)) tf.fail("percentile", "must be in (0, 100]");
        }
        if (f.type == FieldSpec::Type::rotational_kinetic_energy && !s.rotation)
          tf.fail("type", "rotational_kinetic_energy needs rotating particles (particles.rotation = true)");
        if (f.type == FieldSpec::Type::energy) f.term = type;
        f.every = tf.integer_or("every", 1);
        if (f.every < 1) tf.fail("every", fmt::format("must be >= 1, got {}", f.every));
        if (f.per_wall()) {
          f.wall = tf.string("wall");
          bool found = false;
          for (const auto& w : s.walls) found = found || w.name == f.wall;
          for (const auto& w : s.mesh_walls) found = found || w.name == f.wall;
          if (!found) tf.fail("wall", fmt::format("no wall named \"{}\" (planar or mesh)", f.wall));
        }
        if (f.type == FieldSpec::Type::mass_below || f.type == FieldSpec::Type::mean_vz_above) {
          f.z = tf.number("z");
          if (!std::isfinite(f.z)) tf.fail("z", "must be finite");
        }
        // Two savers of the same values would write two columns of one name: refused. Two of one name with
        // other parameters (a runout's direction or origin, a height z) both save: the later one's
        // columns take the suffix "_fields<k>" (k its index in output.fields).
        for (std::size_t j = 0; j < s.fields.size(); ++j) {
          const auto& earlier = s.fields[j];
          if (earlier.base_name() != f.base_name() || earlier.wall != f.wall) continue;
          if (!earlier.same_values(f)) {
            f.suffix = fmt::format("_fields{}", k);
            continue;
          }
          const bool wall = f.per_wall();
          const bool force = f.type == FieldSpec::Type::wall_force;
          tf.fail(
              wall ? "wall" : "type",
              fmt::format("{} is saved already by output.fields[{}] with the same parameters: two savers "
                          "would write the same column {} twice; keep one (its every = N sets how often)",
                          wall ? fmt::format("the {} of wall \"{}\"", force ? "force" : "position", f.wall)
                               : fmt::format("\"{}\"", f.name()),
                          j, wall ? fmt::format("{}_{}_x/y/z", f.name(), f.wall) : f.name()));
        }
        tf.finish();
        s.fields.push_back(std::move(f));
      }
    }
    t.finish();
  }
  if (const auto* arr = top.table_array("insert"))
    for (std::size_t k = 0; k < arr->size(); ++k) {
      TableReader t(*(*arr)[k].as_table(), label, fmt::format("insert[{}]", k));
      s.inserts.push_back(parse_insert(t, s.density));
    }
  if (const auto* arr = top.table_array("delete"))
    for (std::size_t k = 0; k < arr->size(); ++k) {
      TableReader t(*(*arr)[k].as_table(), label, fmt::format("delete[{}]", k));
      s.deletes.push_back(parse_delete(t));
    }
  if (const auto* arr = top.table_array("stages")) {
    for (std::size_t k = 0; k < arr->size(); ++k) {
      TableReader t(*(*arr)[k].as_table(), label, fmt::format("stages[{}]", k));
      s.stages.push_back(parse_stage(t, s.walls, s.fields));
    }
  }
  top.finish();
  return s;
}

Scene parse_scene(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot open the scene file", file.string()));
  std::error_code ec;
  if (const auto size = fs::file_size(file, ec); !ec && size > kMaxSceneBytes)
    throw InputError(scene_too_large(file.string(), size));
  std::stringstream ss;
  ss << in.rdbuf();
  Scene s = parse_scene_text(ss.str(), file.string(), file.parent_path());
  s.file = file;
  return s;
}

std::vector<std::string> field_columns(const FieldSpec& f) {
  std::vector<std::string> cols;
  if (f.type == FieldSpec::Type::broken_bonds) {
    for (const char* m : {"tension", "shear", "bending", "torsion"})
      cols.push_back(fmt::format("broken_bonds_{}", m));
  } else if (!f.per_wall()) {
    cols.push_back(f.name());
  } else {
    for (const char* c : {"x", "y", "z"}) cols.push_back(fmt::format("{}_{}_{}", f.name(), f.wall, c));
  }
  return cols;
}

std::vector<std::string> field_columns(const Scene& scene) {
  std::vector<std::string> cols;
  for (const auto& f : scene.fields)
    for (auto& c : field_columns(f)) cols.push_back(std::move(c));
  return cols;
}

}  // namespace basalt::solver
