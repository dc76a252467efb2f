// Load balancing at rebuilds (run.balance = "count" or "time", docs/solver.md "Load balancing"): when
// the busiest rank owns more than run.balance_threshold x the mean particles ("count"), or took more
// than that x the mean compute time over the last run.balance_every steps ("time"), the cut planes of
// the rank grid move to where the global marginal along each axis of the particles (each weighted by its
// rank's time per particle for "time") splits evenly (parallel/balance.hpp), and the particles, with
// their bonds and contact history, migrate to their new owners.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "basalt/solver/parallel/balance.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

namespace {
/// Bins of the marginal histogram along each axis: a slab's count is within one bin's count of the
/// target; 3 x 4096 doubles are one 96 KiB reduction, made only when the threshold is exceeded.
constexpr std::size_t kBalanceBins = 4096;
}  // namespace

template <class Real>
double Simulation<Real>::imbalance() const {
  const double mean = double(n_global_) / comm().size();
  return comm().max(double(p_.n_owned)) / mean;
}

template <class Real>
bool Simulation<Real>::time_balance_due() {
  // Whole microseconds: the integer sums are exact, so every rank reaches the same decision and weights.
  const auto work = static_cast<long long>(std::llround(1e6 * (work_total() - work_mark_)));
  const long long most = comm().max(work), total = comm().sum(work);
  time_imbalance_ = total > 0 ? double(most) * comm().size() / double(total) : 1.0;
  time_weight_ = time_weight(work, static_cast<long long>(p_.n_owned), total, n_global_);
  balance_by_time_ = time_imbalance_ > scene_.balance_limit();
  if (!balance_by_time_) {
    work_mark_ = work_total();
    work_window_start_ = step_;
  }
  return balance_by_time_;
}

template <class Real>
void Simulation<Real>::balance_at_rebuild() {
  // "time" moves the cuts only when its check asked for it, or at the first rebuild (no time measured
  // yet: by count); any other rebuild leaves them.
  const bool by_time = balance_by_time_;
  balance_by_time_ = false;
  if (scene_.balance == "time" && !by_time && rebuilds_ > 0) return;
  const double before = by_time ? time_imbalance_ : imbalance();
  const double weight = by_time ? time_weight_ : 1.0;
  const std::int64_t window = step_ - work_window_start_;
  if (by_time) {  // the next window starts now, whether or not the cuts move
    work_mark_ = work_total();
    work_window_start_ = step_;
  }
  if (before <= scene_.balance_limit()) return;
  const double particles_before = by_time ? imbalance() : before;
  // The owned particles' extent, then their counts along each axis over it (one reduction).
  std::array<double, 3> lo{}, hi{};
  for (int d = 0; d < 3; ++d) {
    const auto& c = d == 0 ? p_.x : (d == 1 ? p_.y : p_.z);
    double a = std::numeric_limits<double>::infinity(), b = -a;
    for (std::size_t i = 0; i < p_.n_owned; ++i) {
      a = std::min(a, double(c[i]));
      b = std::max(b, double(c[i]));
    }
    lo[static_cast<std::size_t>(d)] = comm().min(a);
    hi[static_cast<std::size_t>(d)] = comm().max(b);
  }
  std::vector<double> counts(3 * kBalanceBins, 0.0);
  std::array<std::vector<double>, 3> cuts;
  for (int d = 0; d < 3; ++d) {
    const auto k = static_cast<std::size_t>(d);
    cuts[k] = dec_->cuts(d);
    if (dec_->dims()[d] == 1) continue;
    AxisHistogram h(lo[k], hi[k], kBalanceBins);
    const auto& c = d == 0 ? p_.x : (d == 1 ? p_.y : p_.z);
    for (std::size_t i = 0; i < p_.n_owned; ++i) h.add(double(c[i]), weight);
    std::copy(h.counts.begin(), h.counts.end(),
              counts.begin() + static_cast<std::ptrdiff_t>(k * kBalanceBins));
  }
  comm().sum_all(counts);
  for (int d = 0; d < 3; ++d) {
    const auto k = static_cast<std::size_t>(d);
    if (dec_->dims()[d] == 1) continue;
    AxisHistogram h(lo[k], hi[k], kBalanceBins);
    std::copy(counts.begin() + static_cast<std::ptrdiff_t>(k * kBalanceBins),
              counts.begin() + static_cast<std::ptrdiff_t>((k + 1) * kBalanceBins), h.counts.begin());
    cuts[k] = balanced_cuts(h, dec_->dims()[d], ghost_width_);
    // Keep an axis's cuts unless the new ones shrink its largest slab by 1 %: a scene whose grains cannot
    // be split finer (or whose imbalance is not along the axes' marginals) is not migrated at every rebuild.
    if (!(largest_slab(h, cuts[k]) < 0.99 * largest_slab(h, dec_->cuts(d)))) cuts[k] = dec_->cuts(d);
  }
  if (cuts[0] == dec_->cuts(0) && cuts[1] == dec_->cuts(1) && cuts[2] == dec_->cuts(2)) return;
  dec_->set_cuts(cuts);
  auto error = halo_->migrate(p_, bonds_, forces_.pending_history(), true);
  error = comm().agree_error(error);
  if (error) stop(*error);
  const long long total = comm().sum(static_cast<long long>(p_.n_owned));
  if (total != n_global_)
    stop(
        fmt::format("step {}: {} particles on the ranks after re-balancing, {} expected: particles were lost",
                    step_, total, n_global_));
  ++rebalances_;
  imbalance_before_ = before;
  const double after = imbalance();
  if (comm().rank() != 0) return;
  if (by_time)
    fmt::print(
        "balance: step {}: max/mean compute time per rank {:.3f} over the last {} steps; max/mean particles "
        "per rank {:.3f} -> {:.3f} (run.balance = \"time\", threshold {})\n",
        step_, before, window, particles_before, after, scene_.balance_limit());
  else
    fmt::print(
        "balance: step {}: max/mean particles per rank {:.3f} -> {:.3f} (run.balance = \"{}\", "
        "threshold {})\n",
        step_, before, after, scene_.balance, scene_.balance_limit());
}

#define BASALT_INSTANTIATE(R)                        \
  template double Simulation<R>::imbalance() const;  \
  template void Simulation<R>::balance_at_rebuild(); \
  template bool Simulation<R>::time_balance_due();
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
