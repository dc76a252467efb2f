#pragma once
// One [[stages]] entry of a scene (docs/scenes.md, "Stages"): the changes made at its start, then its steps,
// or steps until a condition holds. basalt-run (and basalt.Simulation.run_stages) runs the stages in order
// (solver/stages.hpp).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace basalt::solver {

struct StageSpec {
  std::string name;
  /// The stage's steps, or with a condition the most it may take.
  std::int64_t steps = 0;

  // The condition that ends it early (checked every `every` steps); none when until is false.
  bool until = false;
  std::int64_t every = 100;
  double kinetic_energy_below = -1;  ///< the total kinetic energy falls below this (when >= 0)
  std::optional<double> time_above;  ///< or: the run's time reaches this (the time since the run began)
  std::string wall;                  ///< or: the force on this wall (summed over ranks) along `axis`
  int axis = 2;
  std::string saver;                   ///< or: this column of fields.csv, as its saver computes it
  std::size_t saver_column = 0;        ///< its index in field_columns(scene)
  std::optional<double> above, below;  ///< wall_force and saver: the value passes above or below this

  // The changes at its start.
  std::vector<std::string> remove_walls;
  std::vector<std::string>
      add_walls;  ///< walls that touch particles from the stage's start (Simulation::add_wall)
  std::vector<std::pair<std::string, std::array<double, 3>>> wall_velocity;
  std::optional<std::vector<std::int64_t>> fixed_tags;
  double dt = 0;  ///< a new time step (0: unchanged)
};

}  // namespace basalt::solver
