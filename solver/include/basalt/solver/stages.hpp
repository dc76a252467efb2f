#pragma once
// Staged runs (docs/scenes.md, "Stages"): each [[stages]] entry's changes (walls removed or moved at a
// velocity, fixed tags, dt), then its steps through the one run loop with a hook that ends the stage when its
// condition holds (the kinetic energy below a value, a wall's force past a value). Collective.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "basalt/solver/output/output_sink.hpp"
#include "basalt/solver/scene/stage_spec.hpp"
#include "basalt/solver/scene/table_reader.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

/// Parses one [[stages]] table (its keys checked; wall names against the scene's planar walls).
StageSpec parse_stage(TableReader& t, const std::vector<WallSpec>& walls);

/// What happened in a stage (for the report line).
struct StageReport {
  std::string name;
  std::int64_t first_step = 0, steps = 0;
  bool condition_met = false;
  double value = 0;  ///< the condition's quantity at the stage's end (kinetic energy or wall force)
};

/// Runs the stages in order through `out`; calls `report` after each (every rank). Returns the steps made.
template <class Real>
std::int64_t run_stages(Simulation<Real>& sim, OutputSink& out, const std::vector<StageSpec>& stages,
                        const std::function<void(const StageSpec&, const StageReport&)>& report = {});

/// "stage settle: steps 1-4200 (kinetic energy 9.1e-07 < 1e-06 at step 4200)" and the like.
std::string describe(const StageSpec& stage, const StageReport& r);

}  // namespace basalt::solver
