// Load balancing at rebuilds (run.balance = "count", "pairs" or "time", docs/solver.md "Load balancing"):
// when the busiest rank owns more than run.balance_threshold x the mean particles ("count"), or x the mean
// work its neighbour lists, bonds and walls give it ("pairs"), or took more than that x the mean compute
// time over the last run.balance_every steps ("time"), the cut planes of the rank grid move to where the
// global marginal along each axis of the particles (each weighted by its work for "pairs", by its rank's
// time per particle for "time") splits evenly (parallel/balance.hpp), and the particles, with their bonds
// and contact history, migrate to their new owners.
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

/// The owned particles' extent along each axis over all ranks (min and max reductions), then their
/// marginal histograms over it along each axis the grid splits, particle i weighted by weight(i), summed
/// over the ranks (one reduction): the same on every rank, whichever rank holds which particle.
template <class Real, class Weight>
BalanceMarginals marginals(const Particles<Real>& p, const Decomposition& dec, Weight&& weight) {
  BalanceMarginals m;
  for (int d = 0; d < 3; ++d) {
    const auto& c = d == 0 ? p.x : (d == 1 ? p.y : p.z);
    double a = std::numeric_limits<double>::infinity(), b = -a;
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      a = std::min(a, double(c[i]));
      b = std::max(b, double(c[i]));
    }
    m.lo[static_cast<std::size_t>(d)] = dec.comm().min(a);
    m.hi[static_cast<std::size_t>(d)] = dec.comm().max(b);
  }
  m.counts.assign(3 * kBalanceBins, 0.0);
  for (int d = 0; d < 3; ++d) {
    const auto k = static_cast<std::size_t>(d);
    if (dec.dims()[d] == 1) continue;
    AxisHistogram h(m.lo[k], m.hi[k], kBalanceBins);
    const auto& c = d == 0 ? p.x : (d == 1 ? p.y : p.z);
    for (std::size_t i = 0; i < p.n_owned; ++i) h.add(double(c[i]), weight(i));
    std::copy(h.counts.begin(), h.counts.end(),
              m.counts.begin() + static_cast<std::ptrdiff_t>(k * kBalanceBins));
  }
  dec.comm().sum_all(m.counts);
  return m;
}
}  // namespace

template <class Real>
std::vector<double> Simulation<Real>::pair_work() const {
  // Whole numbers in units of roughly 50 instructions of a step (callgrind, the granular bench pile): a
  // particle's integration 2; each end of a listed pair 1 (the test whether it touches), and 3 more while
  // it touches (the contact law, its gathers and scatters); each end of a bond 3; a wall candidate 4. A
  // pair or bond with a ghost gives both ends' share to the owned end: its rank evaluates all of it (and
  // so does the ghost's).
  const std::size_t n = p_.n_owned;
  std::vector<double> w(n, 2.0);
  const auto touching = [&](std::size_t i, std::size_t j) {
    const double dx = double(p_.x[i]) - double(p_.x[j]), dy = double(p_.y[i]) - double(p_.y[j]),
                 dz = double(p_.z[i]) - double(p_.z[j]), rs = double(p_.radius[i]) + double(p_.radius[j]);
    return dx * dx + dy * dy + dz * dz < rs * rs;
  };
  const auto& own = forces_.own_pairs();
  const auto& ghost = forces_.ghost_pairs();
  for (const PairList* list : {&own, &ghost}) {
    if (list->offset.size() != n + 1) continue;
    for (std::size_t i = 0; i < n; ++i)
      for (auto e = list->offset[i]; e < list->offset[i + 1]; ++e) {
        const auto j = static_cast<std::size_t>(list->neigh[e]);
        if (j >= p_.size()) continue;
        const double end = touching(i, j) ? 4 : 1;
        w[i] += end;
        w[j < n ? j : i] += end;
      }
  }
  for (std::size_t k = 0; k < bonds_.ia.size(); ++k) {
    const auto a = static_cast<std::size_t>(bonds_.ia[k]), b = static_cast<std::size_t>(bonds_.ib[k]);
    if (a >= n) continue;
    w[a] += 3;
    w[b < n ? b : a] += 3;
  }
  const auto& walls = forces_.walls();
  for (std::size_t k = 0; k < walls.size(); ++k)
    for (const auto i : walls.candidates(k))
      if (static_cast<std::size_t>(i) < n) w[static_cast<std::size_t>(i)] += 4;
  for (std::size_t k = 0; k < walls.meshes(); ++k)
    for (const auto i : walls.mesh_candidates(k))
      if (static_cast<std::size_t>(i) < n) w[static_cast<std::size_t>(i)] += 4;
  return w;
}

template <class Real>
void Simulation<Real>::weigh_pairs() {
  // Whole numbers below 2^53: the sums are exact, so every rank reaches the same decision and cuts.
  const auto w = pair_work();
  double load = 0;
  for (const double v : w) load += v;
  const double most = comm().max(load), total = comm().sum(load);
  pairs_imbalance_ = total > 0 ? most * comm().size() / total : 1.0;
  pairs_weighed_ = true;
  if (pairs_imbalance_ > scene_.balance_limit())
    pairs_marginals_ = marginals(p_, *dec_, [&](std::size_t i) { return w[i]; });
}

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
  // "pairs" weighed the particles before this rebuild's migration (weigh_pairs: the lists were still
  // those of the particles' indices); at the first rebuild, with no lists yet, it balances by count.
  const bool by_pairs = pairs_weighed_;
  pairs_weighed_ = false;
  BalanceMarginals weighed = std::move(pairs_marginals_);
  pairs_marginals_ = {};
  if (scene_.balance == "time" && !by_time && rebuilds_ > 0) return;
  const double before = by_time ? time_imbalance_ : by_pairs ? pairs_imbalance_ : imbalance();
  const double weight = by_time ? time_weight_ : 1.0;
  const std::int64_t window = step_ - work_window_start_;
  if (by_time) {  // the next window starts now, whether or not the cuts move
    work_mark_ = work_total();
    work_window_start_ = step_;
  }
  if (before <= scene_.balance_limit()) return;
  const double particles_before = by_time || by_pairs ? imbalance() : before;
  const BalanceMarginals m =
      by_pairs ? std::move(weighed) : marginals(p_, *dec_, [&](std::size_t) { return weight; });
  const auto& lo = m.lo;
  const auto& hi = m.hi;
  const auto& counts = m.counts;
  std::array<std::vector<double>, 3> cuts;
  for (int d = 0; d < 3; ++d) cuts[static_cast<std::size_t>(d)] = dec_->cuts(d);
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
  if (by_pairs)
    fmt::print(
        "balance: step {}: max/mean work per rank {:.3f} (particles, listed pairs, bonds, wall candidates); "
        "max/mean particles per rank {:.3f} -> {:.3f} (run.balance = \"pairs\", threshold {})\n",
        step_, before, particles_before, after, scene_.balance_limit());
  else if (by_time)
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

#define BASALT_INSTANTIATE(R)                                    \
  template double Simulation<R>::imbalance() const;              \
  template std::vector<double> Simulation<R>::pair_work() const; \
  template void Simulation<R>::weigh_pairs();                    \
  template void Simulation<R>::balance_at_rebuild();             \
  template bool Simulation<R>::time_balance_due();
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
