#pragma once
// When the neighbour lists are rebuilt next, and what the last rebuild was: the state the step's rebuild test
// (Simulation::refresh_neighbours) reads and the rebuild (Simulation::rebuild) writes. Owned by Simulation;
// free of MPI (the caller takes the ranks' largest need() before asking exceeded(), so every rank agrees).
//
//   limit2      (skin / 2)^2: a particle or wall that moved farther since the last rebuild may meet a pair
//               the lists miss. Set by configure() at the start (both constructors).
//   pending     a bond broke and the lists do not know: the pair, unbonded, must become a contact candidate,
//               so the next step rebuilds whatever moved. Set by bond_parted() (a force computation that
//               broke a bond where the lists do not mark bonded pairs) and by a restart from the checkpoint's
//               rebuild_pending; cleared by every rebuild (rebuilt()); the critical-step estimate, which
//               breaks bonds on trial, puts it back (set_pending()).
//   far_moves   the blow-up check let fast particles in free flight go on: the next migration may carry
//               them across several ranks' regions. Set by allow_far_moves(), taken (cleared) by the
//               migration (take_far_moves()).
//   count       rebuilds so far (rebuilt()); last_step: the step whose positions the last rebuild used
//               (checkpoints store it with the positions at that rebuild, for a restart's replay).
#include <cstdint>
#include <limits>

namespace basalt::solver {

class RebuildSchedule {
 public:
  /// The skin the lists are built with (run.skin).
  void configure(double skin) { limit2_ = 0.25 * skin * skin; }

  /// This rank's need for a rebuild: infinite when a bond broke unknown to the lists or `other` (the
  /// balancer, particles entering or leaving), else the largest squared move since the last rebuild.
  double need(double moved2, bool other) const { return pending_ || other ? kInfinite : moved2; }
  /// Whether the ranks' largest need calls for a rebuild (a non-finite move does: NaN compares false).
  bool exceeded(double need) const { return !(need <= limit2_); }

  /// A bond broke and the lists do not mark bonded pairs: the next step rebuilds.
  void bond_parted() { pending_ = true; }
  bool pending() const { return pending_; }
  /// A restart's rebuild_pending, or the state before a trial that broke bonds (the critical-step estimate).
  void set_pending(bool pending) { pending_ = pending; }

  /// The fast particles the blow-up check let go on: the next migration may go any distance.
  void allow_far_moves() { far_moves_ = true; }
  /// Whether the migration about to run may go any distance; it may once.
  bool take_far_moves() {
    const bool far = far_moves_;
    far_moves_ = false;
    return far;
  }

  /// The lists were rebuilt from the positions of `step`: counted, and nothing pending any more.
  void rebuilt(std::int64_t step) {
    last_step_ = step;
    pending_ = false;
    ++count_;
  }
  /// A rebuild inside a step used the positions of the step being completed (one after the clock's).
  void set_last_step(std::int64_t step) { last_step_ = step; }

  std::int64_t count() const { return count_; }
  std::int64_t last_step() const { return last_step_; }

 private:
  static constexpr double kInfinite = std::numeric_limits<double>::infinity();
  double limit2_ = 0;
  bool pending_ = false;
  bool far_moves_ = false;
  std::int64_t count_ = 0;
  std::int64_t last_step_ = 0;
};

}  // namespace basalt::solver
