#pragma once
// Load balancing at rebuilds (run.balance = "count", "pairs" or "time", docs/solver.md "Load balancing"):
// the balancer's own state between rebuilds (its measuring window, the decisions of its checks, the times
// it moved the cuts) and the decisions themselves. It holds no reference to the run: each call is given
// the parts it reads or moves (LoadBalancer::Run), so Simulation owns one and calls it at its rebuilds.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "basalt/solver/core/bonds.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/interactions/force_field.hpp"
#include "basalt/solver/parallel/balance.hpp"
#include "basalt/solver/parallel/communicator.hpp"
#include "basalt/solver/parallel/decomposition.hpp"
#include "basalt/solver/parallel/halo.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/timers.hpp"

namespace basalt::solver {

template <class Real>
class LoadBalancer {
 public:
  /// The parts of a run a balancing call reads (the scene's run.balance settings, the phase times, the
  /// step) and, at a rebuild that moves the cuts, changes: the decomposition's cuts, and the particles
  /// with their bonds and contact history, which migrate through the halo to their new owners.
  struct Run {
    const Scene& scene;
    Decomposition& dec;
    Halo<Real>& halo;
    Particles<Real>& p;
    Bonds<Real>& bonds;
    const ForceField<Real>& forces;
    const PhaseTimes& times;
    std::int64_t n_global = 0;
    std::int64_t step = 0;
    std::int64_t rebuilds = 0;  ///< rebuilds before this one
    double ghost_width = 0;
  };

  /// Collective: the busiest rank's owned particles over the mean (1 = perfectly balanced).
  static double imbalance(const Particles<Real>& p, const Comm& comm, std::int64_t n_global);
  /// run.balance = "pairs"'s estimate of each owned particle's work in a step, a whole number (units of
  /// about 50 instructions): 2 for the particle; per end of a listed pair 1, 4 while the pair touches; per
  /// end of a bond 3; 4 per wall or mesh the particle is a candidate of. A pair or bond with a ghost puts
  /// both ends' share on the owned end (this rank evaluates all of it). From the lists and bonds of the last
  /// rebuild, at the current positions (2 each before the first).
  static std::vector<double> pair_work(const Particles<Real>& p, const ForceField<Real>& forces,
                                       const Bonds<Real>& bonds);

  /// Collective, with run.balance = "pairs", in a rebuild before its migration (the lists still index the
  /// particles): each rank's work (pair_work) against the mean, and when that exceeds the threshold the
  /// weighted marginals at_rebuild then cuts by.
  void weigh_pairs(const Run& run);
  /// Collective, every run.balance_every steps with run.balance = "time": whether the busiest rank's compute
  /// time since the last check exceeds the mean by the threshold (then the step rebuilds and re-balances);
  /// otherwise starts a new measuring window.
  bool time_balance_due(const Run& run);
  /// Collective, in a rebuild after migration: with run.balance = "count" (and "time" at its first
  /// rebuild), moves the cuts when the busiest rank exceeds the mean particles by run.balance_threshold,
  /// and migrates to them; with "time" after a time_balance_due() that said yes, moves them by the
  /// particles' time weights (parallel/balance.hpp, time_weight); with "pairs" after weigh_pairs, by the
  /// particles' work. Returns the error (agreed across ranks) that must stop the run: a particle the
  /// migration could not place, or particles lost.
  std::optional<std::string> at_rebuild(const Run& run);

  /// run.balance = "time": adds seconds to this rank's measured compute time, as if its steps had taken
  /// them (the balancer then moves work off this rank; tests stand in for a slower core with it).
  void add_rank_work(double seconds) { extra_work_ += seconds; }
  /// This rank's compute time so far (forces and integration, and add_rank_work's).
  double work_total(const PhaseTimes& times) const { return times.forces + times.integration + extra_work_; }
  /// Times the cuts moved, and the imbalance (of particles, work or compute time) before the last move.
  std::int64_t rebalances() const { return rebalances_; }
  double imbalance_before_last_rebalance() const { return imbalance_before_; }
  /// A restart replaying a rebuild with the checkpoint's own cuts: no check nor move while paused.
  bool paused() const { return paused_; }
  void set_paused(bool paused) { paused_ = paused; }

 private:
  std::int64_t rebalances_ = 0;
  double imbalance_before_ = 1;
  bool paused_ = false;
  double extra_work_ = 0;               ///< add_rank_work's seconds
  double work_mark_ = 0;                ///< work_total() when the time balancer's window began
  std::int64_t work_window_start_ = 0;  ///< the step it began
  bool by_time_ = false;                ///< set by time_balance_due(): the next rebuild moves the cuts
  double time_weight_ = 1024;           ///< this rank's particles' weight for that move
  double time_imbalance_ = 1;           ///< max/mean compute time per rank at that check
  bool pairs_weighed_ = false;          ///< weigh_pairs() ran in this rebuild
  double pairs_imbalance_ = 1;          ///< max/mean pair_work per rank it found
  BalanceMarginals pairs_marginals_;    ///< its weighted marginals (when above the threshold)
};

extern template class LoadBalancer<double>;
extern template class LoadBalancer<float>;

}  // namespace basalt::solver
