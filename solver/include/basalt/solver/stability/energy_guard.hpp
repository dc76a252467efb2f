#pragma once
// The energy ledger's guard (core/ledger.hpp, docs/solver.md): mechanical energy + dissipated - work put in
// stays at a reference E0, the start's mechanical energy (or the balance after particles came or went).
// Allowed growth: |E0| + the work put in + what was dissipated + how far each body force's potential moved
// (energy it released): an error of 100 % of every source at once; without body forces or dissipation,
// E > 2 (E0 + W). It holds the reference, this rank's share of the walls' positive work (the ledger's
// wall_work_in), and which steps need the energies. Free of MPI: the caller sums the ledger over the ranks.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "basalt/solver/core/ledger.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::solver {

class EnergyGuard {
 public:
  /// The guard of scene.energy_check_every (0: never), and the steps scene.fields' energy savers read the
  /// energies at (their terms are `ledger`'s).
  EnergyGuard(const Scene& scene, const Ledger& ledger);

  /// Whether the guard checks at step s.
  bool due(std::int64_t s) const { return every_ > 0 && s % every_ == 0; }
  /// Whether step s needs the potentials (a saver of a potential or of the total energy, or the guard).
  bool energy_due(std::int64_t s) const { return any_due(potential_every_, s) || due(s); }
  /// Whether step s needs the kinetic energy (a saver of it or of the total energy, or the guard).
  bool kinetic_due(std::int64_t s) const { return any_due(kinetic_every_, s) || due(s); }

  /// Adds the walls' work over a step of dt at `power` (this rank's), when positive (work put in).
  void add_wall_work(double power, double dt) { wall_work_in_ += std::max(0.0, power) * dt; }
  /// This rank's share of the positive work the walls did since the reference (ledger term wall_work_in).
  double wall_work_in() const { return wall_work_in_; }
  /// The walls' work counts from zero (a state changed from outside: a new start).
  void clear_wall_work() { wall_work_in_ = 0; }

  /// A start: E0 = the mechanical energy of `v`, the ledger's global values.
  void start(const Ledger& ledger, std::vector<double> v) {
    ledger0_ = std::move(v);
    energy0_ = ledger.mechanical(ledger0_);
  }
  /// After particles came or went: the ledger balances from here, E0 = mechanical + dissipated - work in.
  void rebase(const Ledger& ledger, std::vector<double> v) {
    ledger0_ = std::move(v);
    energy0_ = ledger.mechanical(ledger0_) + ledger.sum(ledger0_, Ledger::Kind::dissipated) -
               ledger.sum(ledger0_, Ledger::Kind::work);
  }

  /// An energy growing without a source, by the ledger's terms.
  struct Breach {
    double mechanical, dissipated, work, imbalance, allowed, energy0;
  };
  /// The balance of `v` (the ledger's global values now); is_body(t): term t is a body force's potential.
  /// nullopt while it holds and the mechanical energy is finite.
  template <class IsBody>
  std::optional<Breach> breach(const Ledger& ledger, const std::vector<double>& v, IsBody is_body) const {
    const double e = ledger.mechanical(v), w = ledger.sum(v, Ledger::Kind::work),
                 d = ledger.sum(v, Ledger::Kind::dissipated);
    double released = 0;
    for (std::size_t t = 0; t < v.size(); ++t)
      if (is_body(t)) released += std::abs(v[t] - ledger0_[t]);
    const double imbalance = e + d - w - energy0_, allowed = std::abs(energy0_) + w + d + released;
    if (imbalance <= allowed && std::isfinite(e)) return std::nullopt;
    return Breach{e, d, w, imbalance, allowed, energy0_};
  }

 private:
  static bool any_due(const std::vector<std::int64_t>& every, std::int64_t s) {
    return std::any_of(every.begin(), every.end(), [s](std::int64_t k) { return s % k == 0; });
  }

  std::int64_t every_ = 0;                     ///< run.energy_check_every
  std::vector<std::int64_t> potential_every_;  ///< the every of each saver that reads potentials
  std::vector<std::int64_t> kinetic_every_;    ///< the every of each saver that reads the kinetic energy
  double energy0_ = 0;                         ///< the reference E0
  std::vector<double> ledger0_;                ///< the ledger's global values at the reference
  double wall_work_in_ = 0;
};

}  // namespace basalt::solver
