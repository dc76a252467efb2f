// Load balancing at rebuilds (run.balance = "count", "pairs" or "time", docs/solver.md "Load balancing"):
// when the busiest rank owns more than run.balance_threshold x the mean particles ("count"), or x the mean
// work its neighbour lists, bonds and walls give it ("pairs"), or took more than that x the mean compute
// time over the last run.balance_every steps ("time"), the cut planes of the rank grid move to where the
// global marginal along each axis of the particles (each weighted by its work for "pairs", by its rank's
// time per particle for "time") splits evenly (parallel/balance.hpp), and the particles, with their bonds
// and contact history, migrate to their new owners.
#include "basalt/solver/parallel/load_balancer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "basalt/solver/parallel/balance.hpp"

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
std::vector<double> LoadBalancer<Real>::pair_work(const Particles<Real>& p, const ForceField<Real>& forces,
                                                  const Bonds<Real>& bonds) {
  // Whole numbers in units of roughly 50 instructions of a step (callgrind, the granular bench pile): a
  // particle's integration 2; each end of a listed pair 1 (the test whether it touches), and 3 more while
  // it touches (the contact law, its gathers and scatters); each end of a bond 3; a wall candidate 4. A
  // pair or bond with a ghost gives both ends' share to the owned end: its rank evaluates all of it (and
  // so does the ghost's).
  const std::size_t n = p.n_owned;
  std::vector<double> w(n, 2.0);
  const auto touching = [&](std::size_t i, std::size_t j) {
    const double dx = double(p.x[i]) - double(p.x[j]), dy = double(p.y[i]) - double(p.y[j]),
                 dz = double(p.z[i]) - double(p.z[j]), rs = double(p.radius[i]) + double(p.radius[j]);
    return dx * dx + dy * dy + dz * dz < rs * rs;
  };
  const auto& own = forces.own_pairs();
  const auto& ghost = forces.ghost_pairs();
  for (const PairList* list : {&own, &ghost}) {
    if (list->offset.size() != n + 1) continue;
    for (std::size_t i = 0; i < n; ++i)
      for (auto e = list->offset[i]; e < list->offset[i + 1]; ++e) {
        const auto j = static_cast<std::size_t>(list->neigh[e]);
        if (j >= p.size()) continue;
        const double end = touching(i, j) ? 4 : 1;
        w[i] += end;
        w[j < n ? j : i] += end;
      }
  }
  for (std::size_t k = 0; k < bonds.ia.size(); ++k) {
    const auto a = static_cast<std::size_t>(bonds.ia[k]), b = static_cast<std::size_t>(bonds.ib[k]);
    if (a >= n) continue;
    w[a] += 3;
    w[b < n ? b : a] += 3;
  }
  const auto& walls = forces.walls();
  for (std::size_t k = 0; k < walls.size(); ++k)
    for (const auto i : walls.candidates(k))
      if (static_cast<std::size_t>(i) < n) w[static_cast<std::size_t>(i)] += 4;
  for (std::size_t k = 0; k < walls.meshes(); ++k)
    for (const auto i : walls.mesh_candidates(k))
      if (static_cast<std::size_t>(i) < n) w[static_cast<std::size_t>(i)] += 4;
  return w;
}

template <class Real>
void LoadBalancer<Real>::weigh_pairs(const Run& run) {
  // Whole numbers below 2^53: the sums are exact, so every rank reaches the same decision and cuts.
  const auto w = pair_work(run.p, run.forces, run.bonds);
  const Comm& comm = run.dec.comm();
  double load = 0;
  for (const double v : w) load += v;
  const double most = comm.max(load), total = comm.sum(load);
  pairs_imbalance_ = total > 0 ? most * comm.size() / total : 1.0;
  pairs_weighed_ = true;
  if (pairs_imbalance_ > run.scene.balance_limit())
    pairs_marginals_ = marginals(run.p, run.dec, [&](std::size_t i) { return w[i]; });
}

template <class Real>
double LoadBalancer<Real>::imbalance(const Particles<Real>& p, const Comm& comm, std::int64_t n_global) {
  const double mean = double(n_global) / comm.size();
  return comm.max(double(p.n_owned)) / mean;
}

template <class Real>
bool LoadBalancer<Real>::time_balance_due(const Run& run) {
  // Whole microseconds: the integer sums are exact, so every rank reaches the same decision and weights.
  const Comm& comm = run.dec.comm();
  const auto work = static_cast<long long>(std::llround(1e6 * (work_total(run.times) - work_mark_)));
  const long long most = comm.max(work), total = comm.sum(work);
  time_imbalance_ = total > 0 ? double(most) * comm.size() / double(total) : 1.0;
  time_weight_ = time_weight(work, static_cast<long long>(run.p.n_owned), total, run.n_global);
  by_time_ = time_imbalance_ > run.scene.balance_limit();
  if (!by_time_) {
    work_mark_ = work_total(run.times);
    work_window_start_ = run.step;
  }
  return by_time_;
}

template <class Real>
std::optional<std::string> LoadBalancer<Real>::at_rebuild(const Run& run) {
  const Scene& scene = run.scene;
  Decomposition& dec = run.dec;
  const Comm& comm = dec.comm();
  auto& p = run.p;
  const std::int64_t step = run.step;
  // "time" moves the cuts only when its check asked for it, or at the first rebuild (no time measured
  // yet: by count); any other rebuild leaves them.
  const bool by_time = by_time_;
  by_time_ = false;
  // "pairs" weighed the particles before this rebuild's migration (weigh_pairs: the lists were still
  // those of the particles' indices); at the first rebuild, with no lists yet, it balances by count.
  const bool by_pairs = pairs_weighed_;
  pairs_weighed_ = false;
  BalanceMarginals weighed = std::move(pairs_marginals_);
  pairs_marginals_ = {};
  if (scene.balance == "time" && !by_time && run.rebuilds > 0) return std::nullopt;
  const double before = by_time    ? time_imbalance_
                        : by_pairs ? pairs_imbalance_
                                   : imbalance(p, comm, run.n_global);
  const double weight = by_time ? time_weight_ : 1.0;
  const std::int64_t window = step - work_window_start_;
  if (by_time) {  // the next window starts now, whether or not the cuts move
    work_mark_ = work_total(run.times);
    work_window_start_ = step;
  }
  if (before <= scene.balance_limit()) return std::nullopt;
  const double particles_before = by_time || by_pairs ? imbalance(p, comm, run.n_global) : before;
  const BalanceMarginals m =
      by_pairs ? std::move(weighed) : marginals(p, dec, [&](std::size_t) { return weight; });
  const auto& lo = m.lo;
  const auto& hi = m.hi;
  const auto& counts = m.counts;
  std::array<std::vector<double>, 3> cuts;
  for (int d = 0; d < 3; ++d) cuts[static_cast<std::size_t>(d)] = dec.cuts(d);
  for (int d = 0; d < 3; ++d) {
    const auto k = static_cast<std::size_t>(d);
    if (dec.dims()[d] == 1) continue;
    AxisHistogram h(lo[k], hi[k], kBalanceBins);
    std::copy(counts.begin() + static_cast<std::ptrdiff_t>(k * kBalanceBins),
              counts.begin() + static_cast<std::ptrdiff_t>((k + 1) * kBalanceBins), h.counts.begin());
    cuts[k] = balanced_cuts(h, dec.dims()[d], run.ghost_width);
    // Keep an axis's cuts unless the new ones shrink its largest slab by 1 %: a scene whose grains cannot
    // be split finer (or whose imbalance is not along the axes' marginals) is not migrated at every rebuild.
    if (!(largest_slab(h, cuts[k]) < 0.99 * largest_slab(h, dec.cuts(d)))) cuts[k] = dec.cuts(d);
  }
  if (cuts[0] == dec.cuts(0) && cuts[1] == dec.cuts(1) && cuts[2] == dec.cuts(2)) return std::nullopt;
  dec.set_cuts(cuts);
  auto error = run.halo.migrate(p, run.bonds, run.forces.pending_history(), true);
  error = comm.agree_error(error);
  if (error) return error;
  const long long total = comm.sum(static_cast<long long>(p.n_owned));
  if (total != run.n_global)
    return fmt::format(
        "step {}: {} particles on the ranks after re-balancing, {} expected: particles were lost", step,
        total, run.n_global);
  ++rebalances_;
  imbalance_before_ = before;
  const double after = imbalance(p, comm, run.n_global);
  if (comm.rank() != 0) return std::nullopt;
  if (by_pairs)
    fmt::print(
        "balance: step {}: max/mean work per rank {:.3f} (particles, listed pairs, bonds, wall candidates); "
        "max/mean particles per rank {:.3f} -> {:.3f} (run.balance = \"pairs\", threshold {})\n",
        step, before, particles_before, after, scene.balance_limit());
  else if (by_time)
    fmt::print(
        "balance: step {}: max/mean compute time per rank {:.3f} over the last {} steps; max/mean particles "
        "per rank {:.3f} -> {:.3f} (run.balance = \"time\", threshold {})\n",
        step, before, window, particles_before, after, scene.balance_limit());
  else
    fmt::print(
        "balance: step {}: max/mean particles per rank {:.3f} -> {:.3f} (run.balance = \"{}\", "
        "threshold {})\n",
        step, before, after, scene.balance, scene.balance_limit());
  return std::nullopt;
}

template class LoadBalancer<double>;
template class LoadBalancer<float>;

}  // namespace basalt::solver
