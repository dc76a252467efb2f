#include "basalt/solver/stages.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "basalt/solver/core/errors.hpp"

namespace basalt::solver {

namespace {

std::size_t find_wall(const TableReader& t, const std::string& key, const std::vector<WallSpec>& walls,
                      const std::string& name) {
  for (std::size_t w = 0; w < walls.size(); ++w)
    if (walls[w].name == name) return w;
  std::string names;
  for (const auto& w : walls) names += (names.empty() ? "" : ", ") + w.name;
  t.fail(key, fmt::format("no planar wall named \"{}\" (the scene's walls: {})", name,
                          names.empty() ? "none" : names));
}

}  // namespace

StageSpec parse_stage(TableReader& t, const std::vector<WallSpec>& walls,
                      const std::vector<FieldSpec>& fields) {
  StageSpec s;
  s.name = t.string_or("name", t.path());
  if (const auto* u = t.subtable("until")) {
    TableReader c(*u, t.file(), t.path() + ".until");
    s.until = true;
    const bool ke = c.has("kinetic_energy_below"), wall = c.has("wall_force"), time = c.has("time_above"),
               saver = c.has("saver");
    if (int(ke) + int(wall) + int(time) + int(saver) != 1)
      c.fail_here(
          "give one condition: kinetic_energy_below = E, time_above = T, wall_force = \"name\" with axis "
          "and above or below, or saver = \"column\" (of fields.csv) with above or below");
    std::int64_t saver_every = 0;
    if (ke) s.kinetic_energy_below = c.non_negative("kinetic_energy_below");
    if (time) s.time_above = c.number("time_above");
    if (wall) {
      s.wall = c.string("wall_force");
      (void)find_wall(c, "wall_force", walls, s.wall);
      const auto axis = c.choice_or("axis", {"x", "y", "z"}, "z");
      s.axis = axis[0] - 'x';
    }
    if (saver) {
      s.saver = c.string("saver");
      std::vector<std::string> names;
      for (const auto& f : fields) {
        const auto first = names.size();
        for (const auto& col : field_columns(f)) names.push_back(col);
        for (auto k = first; k < names.size(); ++k)
          if (names[k] == s.saver) {
            s.saver_column = k;
            saver_every = f.every;
          }
      }
      if (saver_every == 0) {
        std::string list;
        for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
        c.fail("saver", fmt::format("no field saver writes a column \"{}\" (the scene's columns: {}); add "
                                    "it to [[output.fields]]",
                                    s.saver, list.empty() ? "none" : list));
      }
    }
    if (wall || saver) {
      if (c.has("above")) s.above = c.number("above");
      if (c.has("below")) s.below = c.number("below");
      if (s.above.has_value() == s.below.has_value())
        c.fail_here(fmt::format("{}: give one of above = X or below = X", wall ? "wall_force" : "saver"));
    }
    // A saver's value exists at its own steps: checked there, or at a multiple of them.
    s.every = c.integer_or("every", saver ? saver_every : 100);
    if (s.every < 1) c.fail("every", "must be >= 1");
    if (saver && s.every % saver_every != 0)
      c.fail("every", fmt::format("must be a multiple of the saver's every = {}: the column \"{}\" has a "
                                  "value only at those steps",
                                  saver_every, s.saver));
    c.finish();
    if (!t.has("steps"))
      t.fail("until",
             "a stage with a condition needs steps = N too: the most it may take (the stage ends there "
             "if the condition never holds)");
  }
  s.steps = t.integer("steps");
  if (s.steps < 0) t.fail("steps", "must be >= 0");
  if (t.has("remove_walls"))
    for (const auto& name : t.strings_or("remove_walls", {})) {
      (void)find_wall(t, "remove_walls", walls, name);
      s.remove_walls.push_back(name);
    }
  if (t.has("add_walls"))
    for (const auto& name : t.strings_or("add_walls", {})) {
      (void)find_wall(t, "add_walls", walls, name);
      s.add_walls.push_back(name);
    }
  if (const auto* v = t.subtable("wall_velocity")) {
    TableReader c(*v, t.file(), t.path() + ".wall_velocity");
    for (const auto& [key, node] : *v) {
      const std::string name(key.str());
      (void)find_wall(c, name, walls, name);
      s.wall_velocity.emplace_back(name, c.vec3(name));
    }
    c.finish();
  }
  if (t.has("fixed_tags")) s.fixed_tags = t.integers_or("fixed_tags", {});
  if (t.has("dt")) s.dt = t.positive("dt");
  t.finish();
  return s;
}

std::string describe(const StageSpec& stage, const StageReport& r) {
  std::string line = fmt::format("stage {}: steps {}-{}", r.name, r.first_step + 1, r.first_step + r.steps);
  if (!stage.until) return line;
  if (!r.condition_met)
    return line + fmt::format(" (its condition never held: it ran its {} steps)", stage.steps);
  if (stage.kinetic_energy_below >= 0)
    return line + fmt::format(" (kinetic energy {:.4g} < {:.4g})", r.value, stage.kinetic_energy_below);
  if (stage.time_above) return line + fmt::format(" (time {:.6g} >= {:.6g})", r.value, *stage.time_above);
  const auto passed = fmt::format("{:.4g} {} {:.4g}", r.value, stage.above ? ">" : "<",
                                  stage.above ? *stage.above : *stage.below);
  if (!stage.saver.empty()) return line + fmt::format(" ({} {})", stage.saver, passed);
  return line + fmt::format(" (force on {} along {} {})", stage.wall, char('x' + stage.axis), passed);
}

StageProgress StageProgress::parse(const std::string& text, std::size_t stages) {
  StageProgress p;
  std::size_t at = 0;
  while (at <= text.size()) {
    const auto end = std::min(text.find(';', at), text.size());
    try {
      std::size_t used = 0;
      const std::string item = text.substr(at, end - at);
      p.first_steps.push_back(std::stoll(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw InputError(
          fmt::format("the checkpoint's attribute stage_first_steps = \"{}\" is not a list of steps "
                      "separated by ';'",
                      text));
    }
    at = end + 1;
  }
  for (std::size_t k = 1; k < p.first_steps.size(); ++k)
    if (p.first_steps[k] < p.first_steps[k - 1])
      throw InputError(
          fmt::format("the checkpoint's attribute stage_first_steps = \"{}\": steps out of order", text));
  if (p.first_steps.empty() || p.first_steps.size() > stages)
    throw InputError(
        fmt::format("the checkpoint's attribute stage_first_steps = \"{}\" names {} stages; the "
                    "scene has {}: not the scene of this checkpoint",
                    text, p.first_steps.size(), stages));
  return p;
}

std::string StageProgress::text() const {
  std::string t;
  for (std::size_t k = 0; k < first_steps.size(); ++k) {
    if (k > 0) t.push_back(';');
    t.append(std::to_string(first_steps[k]));
  }
  return t;
}

void replay_stages(Scene& scene, const StageProgress& progress) {
  // The same arithmetic as the run's: time_at(step) = base time + (step - base step) x dt; a wall set moving
  // starts from spec.point + its motion's displacement at that time (Walls::move_to, Walls::set_velocity).
  for (std::size_t k = 0; k < progress.first_steps.size(); ++k) {
    const auto& st = scene.stages[k];
    const std::int64_t s = progress.first_steps[k];
    const double dt = scene.clock_base.dt > 0 ? scene.clock_base.dt : scene.dt;
    const double t = scene.clock_base.time + double(s - scene.clock_base.step) * dt;
    for (const auto& name : st.remove_walls)
      for (auto& w : scene.walls)
        if (w.name == name) w.removed = true;
    for (const auto& name : st.add_walls)
      for (auto& w : scene.walls)
        if (w.name == name) w.removed = false;
    for (const auto& [name, v] : st.wall_velocity)
      for (auto& w : scene.walls) {
        if (w.name != name) continue;
        if (w.motion.type == WallMotion::Type::servo)
          throw InputError(
              fmt::format("stage {} sets the servo wall \"{}\" moving: a restart cannot know where "
                          "the servo had it; start the run again",
                          st.name, name));
        const auto u = w.motion.displacement_at(t);
        for (int d = 0; d < 3; ++d) w.point[d] = w.point[d] + u[d];
        WallMotion m;
        m.type = WallMotion::Type::ramp;
        m.velocity = v;
        m.start_time = t;
        w.motion = m;
      }
    if (st.fixed_tags) scene.fixed_tags = *st.fixed_tags;
    if (st.dt > 0) {
      scene.clock_base.time = t;
      scene.clock_base.step = s;
      scene.clock_base.dt = st.dt;
    }
  }
}

template <class Real>
std::int64_t run_stages(Simulation<Real>& sim, OutputSink& out, const std::vector<StageSpec>& stages,
                        const std::function<void(const StageSpec&, const StageReport&)>& report,
                        const StageProgress* resume) {
  std::int64_t total = 0;
  StageProgress progress;
  if (resume) progress = *resume;
  for (std::size_t k = resume ? progress.first_steps.size() - 1 : 0; k < stages.size(); ++k) {
    const auto& st = stages[k];
    std::int64_t steps = st.steps;
    if (resume &&
        k + 1 == progress.first_steps.size()) {  // the stage in progress: its changes are in the scene
      steps = std::max<std::int64_t>(0, st.steps - (sim.current_step() - progress.first_steps[k]));
    } else {
      progress.first_steps.push_back(sim.current_step());
      for (const auto& name : st.remove_walls) sim.remove_wall(name);
      for (const auto& name : st.add_walls) sim.add_wall(name);
      for (const auto& [name, v] : st.wall_velocity) sim.set_wall_velocity(name, v);
      if (st.fixed_tags) sim.set_fixed_tags(*st.fixed_tags);
      if (st.dt > 0) {
        sim.set_dt(st.dt);
        sim.force_rebuild();
      }
    }
    sim.set_checkpoint_attribute("stage_first_steps", progress.text());
    StageReport r{st.name, sim.current_step(), 0, false, 0};
    std::vector<StepHook> hooks;
    if (st.until)
      hooks.push_back({st.every, [&](std::int64_t) {
                         // Collective: every rank computes the same value and decides alike.
                         if (st.kinetic_energy_below >= 0) {
                           r.value = sim.kinetic_energy();
                           r.condition_met = r.value < st.kinetic_energy_below;
                         } else if (st.time_above) {  // (the same clock on every rank)
                           r.value = sim.time();
                           r.condition_met = r.value >= *st.time_above;
                         } else {
                           double f = 0;
                           if (!st.saver.empty()) {
                             // Checked at the saver's steps only (parse_stage): its value is there.
                             const auto v = sim.saved_field(st.saver_column);
                             if (!v) return true;
                             f = *v;
                           } else {
                             const std::size_t w = sim.wall_index(st.wall);
                             f = sim.walls().force(w)[static_cast<std::size_t>(st.axis)];
                             if (sim.comm().size() > 1) f = sim.comm().sum(f);
                           }
                           r.value = f;
                           r.condition_met = st.above ? f > *st.above : f < *st.below;
                         }
                         return !r.condition_met;
                       }});
    r.steps = sim.run(steps, out, hooks);
    total += r.steps;
    if (report) report(st, r);
  }
  return total;
}

template std::int64_t run_stages(Simulation<double>&, OutputSink&, const std::vector<StageSpec>&,
                                 const std::function<void(const StageSpec&, const StageReport&)>&,
                                 const StageProgress*);
template std::int64_t run_stages(Simulation<float>&, OutputSink&, const std::vector<StageSpec>&,
                                 const std::function<void(const StageSpec&, const StageReport&)>&,
                                 const StageProgress*);

}  // namespace basalt::solver
