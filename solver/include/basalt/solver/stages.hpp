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

/// Parses one [[stages]] table (its keys checked; wall names against the scene's planar walls, a saver's
/// column against the scene's field savers).
StageSpec parse_stage(TableReader& t, const std::vector<WallSpec>& walls,
                      const std::vector<FieldSpec>& fields);

/// What happened in a stage (for the report line).
struct StageReport {
  std::string name;
  std::int64_t first_step = 0, steps = 0;
  bool condition_met = false;
  double value = 0;  ///< the condition's quantity at the stage's end (kinetic energy or wall force)
};

/// Where a staged run stood at a checkpoint: the first step of each stage begun (the last is the one in
/// progress). Checkpoints keep it as the root attribute stage_first_steps ("0;300;712").
struct StageProgress {
  std::vector<std::int64_t> first_steps;
  std::string text() const;
  /// From the attribute's text; InputError naming it when it is not steps in order, at most `stages` of them.
  static StageProgress parse(const std::string& text, std::size_t stages);
};

/// A restart's scene: the changes of every stage begun (walls taken away, walls set moving from where their
/// motion had them, fixed tags, dt and the clock's base) applied to the scene itself, so that the run
/// continues with the uninterrupted run's walls and clock to the bit. InputError when a stage set a servo
/// wall moving (its place has no closed form).
void replay_stages(Scene& scene, const StageProgress& progress);

/// Runs the stages in order through `out`; calls `report` after each (every rank). Returns the steps made.
/// With `resume` (a restart, its scene replayed by replay_stages): continues the stage in progress with the
/// steps it has left, without making its changes again, then the rest. A stage that changes dt rebuilds the
/// lists as it begins (a restart's replayed rebuild then never straddles two clocks).
template <class Real>
std::int64_t run_stages(Simulation<Real>& sim, OutputSink& out, const std::vector<StageSpec>& stages,
                        const std::function<void(const StageSpec&, const StageReport&)>& report = {},
                        const StageProgress* resume = nullptr);

/// "stage settle: steps 1-4200 (kinetic energy 9.1e-07 < 1e-06 at step 4200)" and the like.
std::string describe(const StageSpec& stage, const StageReport& r);

}  // namespace basalt::solver
