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

StageSpec parse_stage(TableReader& t, const std::vector<WallSpec>& walls) {
  StageSpec s;
  s.name = t.string_or("name", t.path());
  if (const auto* u = t.subtable("until")) {
    TableReader c(*u, t.file(), t.path() + ".until");
    s.until = true;
    s.every = c.integer_or("every", 100);
    if (s.every < 1) c.fail("every", "must be >= 1");
    const bool ke = c.has("kinetic_energy_below"), wall = c.has("wall_force");
    if (ke == wall)
      c.fail_here(
          "give one condition: kinetic_energy_below = E, or wall_force = \"name\" with axis and above or "
          "below");
    if (ke) s.kinetic_energy_below = c.non_negative("kinetic_energy_below");
    if (wall) {
      s.wall = c.string("wall_force");
      (void)find_wall(c, "wall_force", walls, s.wall);
      const auto axis = c.choice_or("axis", {"x", "y", "z"}, "z");
      s.axis = axis[0] - 'x';
      if (c.has("above")) s.force_above = c.number("above");
      if (c.has("below")) s.force_below = c.number("below");
      if (s.force_above.has_value() == s.force_below.has_value())
        c.fail_here("wall_force: give one of above = F or below = F");
    }
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
  return line + fmt::format(" (force on {} along {} {:.4g} {} {:.4g})", stage.wall, char('x' + stage.axis),
                            r.value, stage.force_above ? ">" : "<",
                            stage.force_above ? *stage.force_above : *stage.force_below);
}

template <class Real>
std::int64_t run_stages(Simulation<Real>& sim, OutputSink& out, const std::vector<StageSpec>& stages,
                        const std::function<void(const StageSpec&, const StageReport&)>& report) {
  std::int64_t total = 0;
  for (const auto& st : stages) {
    for (const auto& name : st.remove_walls) sim.remove_wall(name);
    for (const auto& [name, v] : st.wall_velocity) sim.set_wall_velocity(name, v);
    if (st.fixed_tags) sim.set_fixed_tags(*st.fixed_tags);
    if (st.dt > 0) sim.set_dt(st.dt);
    StageReport r{st.name, sim.current_step(), 0, false, 0};
    std::vector<StepHook> hooks;
    if (st.until)
      hooks.push_back({st.every, [&](std::int64_t) {
                         // Collective: every rank computes the same value and decides alike.
                         if (st.kinetic_energy_below >= 0) {
                           r.value = sim.kinetic_energy();
                           r.condition_met = r.value < st.kinetic_energy_below;
                         } else {
                           const std::size_t w = sim.wall_index(st.wall);
                           double f = sim.walls().force(w)[static_cast<std::size_t>(st.axis)];
                           if (sim.comm().size() > 1) f = sim.comm().sum(f);
                           r.value = f;
                           r.condition_met = st.force_above ? f > *st.force_above : f < *st.force_below;
                         }
                         return !r.condition_met;
                       }});
    r.steps = sim.run(st.steps, out, hooks);
    total += r.steps;
    if (report) report(st, r);
  }
  return total;
}

template std::int64_t run_stages(Simulation<double>&, OutputSink&, const std::vector<StageSpec>&,
                                 const std::function<void(const StageSpec&, const StageReport&)>&);
template std::int64_t run_stages(Simulation<float>&, OutputSink&, const std::vector<StageSpec>&,
                                 const std::function<void(const StageSpec&, const StageReport&)>&);

}  // namespace basalt::solver
