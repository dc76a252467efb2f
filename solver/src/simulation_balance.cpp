// Load balancing at rebuilds (run.balance = "count", docs/solver.md "Load balancing"): when the
// busiest rank owns more than run.balance_threshold x the mean, the cut planes of the rank grid move
// to where the global particle-count marginal along each axis splits evenly (parallel/balance.hpp),
// and the particles, with their bonds and contact history, migrate to their new owners.
#include <fmt/format.h>

#include <algorithm>
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
void Simulation<Real>::balance_at_rebuild() {
  const double before = imbalance();
  if (before <= scene_.balance_threshold) return;
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
    for (std::size_t i = 0; i < p_.n_owned; ++i) h.add(double(c[i]));
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
  if (comm().rank() == 0)
    fmt::print(
        "balance: step {}: max/mean particles per rank {:.3f} -> {:.3f} (run.balance = \"count\", "
        "threshold {})\n",
        step_, before, after, scene_.balance_threshold);
}

#define BASALT_INSTANTIATE(R)                       \
  template double Simulation<R>::imbalance() const; \
  template void Simulation<R>::balance_at_rebuild();
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
