// Neighbour-list rebuilds: the non-finite check, migration (with bonds and contact history), the
// canonical spatial sort, ghosts, bonds resolved to local indices in canonical order, then the
// force field's lists. Every rebuild is canonical: a restart replays one bit for bit.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
std::optional<std::string> Simulation<Real>::check_finite() const {
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    const bool ok = std::isfinite(p_.x[i]) && std::isfinite(p_.y[i]) && std::isfinite(p_.z[i]) &&
                    std::isfinite(p_.vx[i]) && std::isfinite(p_.vy[i]) && std::isfinite(p_.vz[i]) &&
                    std::isfinite(p_.fx[i]) && std::isfinite(p_.fy[i]) && std::isfinite(p_.fz[i]);
    if (!ok)
      return fmt::format(
          "step {}: particle id {} went non-finite: position ({}, {}, {}), velocity ({}, {}, {}), force ({}, "
          "{}, "
          "{}); dt = {} is {:.3g} x the critical time step",
          step_, p_.id[i], p_.x[i], p_.y[i], p_.z[i], p_.vx[i], p_.vy[i], p_.vz[i], p_.fx[i], p_.fy[i],
          p_.fz[i], scene_.dt, stability_.fraction);
  }
  return std::nullopt;
}

template <class Real>
void Simulation<Real>::spatial_sort() {
  // Owned particles in cell order: neighbours in space become neighbours in memory. Within a cell
  // by id, so the order is a function of the owned (id, position) set alone, never of the order
  // migration or a restart left them in: every rebuild is canonical (a restart replays one bit for
  // bit, docs/ARCHITECTURE.md). A cell holds a few particles: sorting them costs little.
  grid_.build(p_.x, p_.y, p_.z, p_.n_owned, contact_cutoff_);
  const auto& order = grid_.order();
  const auto& start = grid_.start();
  std::vector<std::uint32_t> perm(order.begin(), order.end());
  const auto by_id = [&](std::uint32_t i, std::uint32_t j) { return p_.id[i] < p_.id[j]; };
  for (std::size_t c = 0; c + 1 < start.size(); ++c)
    if (start[c + 1] - start[c] > 1) std::sort(perm.begin() + start[c], perm.begin() + start[c + 1], by_id);
  p_.permute_owned(perm);
}

template <class Real>
std::vector<std::uint32_t> Simulation<Real>::resolve_bonds() {
  ids_.assign(p_.id, p_.size());
  std::optional<std::string> error;
  const std::size_t nb = bonds_.size(), n = p_.n_owned;
  bonds_.ia.resize(nb);
  bonds_.ib.resize(nb);
  for (std::size_t k = 0; k < nb; ++k) {
    auto ia = ids_.find(bonds_.a[k]), ib = ids_.find(bonds_.b[k]);
    if ((ia < 0 || ib < 0) && !error) {
      error = fmt::format(
          "step {}: the bond between particle ids {} and {} is longer than the ghost width {:.6g} (particle "
          "{} "
          "is not within reach of rank {}): bonds must not stretch beyond the longest initial bond + skin",
          step_, bonds_.a[k], bonds_.b[k], ghost_width_, ia < 0 ? bonds_.a[k] : bonds_.b[k], comm().rank());
      if (stability_.warn)
        *error += fmt::format(" (dt is {:.3g} x the critical time step: the run is probably unstable)",
                              stability_.fraction);
      ia = std::max(ia, 0);
      ib = std::max(ib, 0);
    }
    // Owned end first; both owned: the lower index first (a canonical orientation, whatever
    // orientation the bond arrived in).
    if (static_cast<std::size_t>(ia) >= n || (static_cast<std::size_t>(ib) < n && ib < ia)) {
      std::swap(ia, ib);
      std::swap(bonds_.a[k], bonds_.b[k]);
    }
    bonds_.ia[k] = ia;
    bonds_.ib[k] = ib;
  }
  if (comm().size() > 1) error = comm().agree_error(error);
  if (error) stop(*error);
  return bonds_.order_canonically(n);
}

template <class Real>
void Simulation<Real>::rebuild() {
  Stopwatch sw;
  auto error = check_finite();
  const bool parallel = comm().size() > 1;
  if (parallel) error = comm().agree_error(error);
  if (error) stop(*error);
  forces_.save_history(p_);  // before the ghosts (and the pairs' ids) go
  p_.drop_ghosts();
  if (parallel) {
    error = halo_->migrate(p_, bonds_, forces_.pending_history());
    error = comm().agree_error(error);
    if (error) stop(*error);
    const long long total = comm().sum(static_cast<long long>(p_.n_owned));
    if (total != n_global_)
      stop(fmt::format("step {}: {} particles on the ranks, {} expected: particles were lost", step_, total,
                       n_global_));
  }
  times_.communication += sw.lap();
  spatial_sort();
  times_.neighbor += sw.lap();
  if (parallel) halo_->build_ghosts(p_, ghost_width_);
  times_.communication += sw.lap();
  const auto bond_bucket_end = resolve_bonds();
  forces_.rebuild_lists(p_, bond_bucket_end, bonds_, scene_.skin, contact_cutoff_);
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    p_.x0[i] = float(p_.x[i]);
    p_.y0[i] = float(p_.y[i]);
    p_.z0[i] = float(p_.z[i]);
  }
  if (p_.with_exact_rebuild) {  // exact copies for the checkpoints (x0 is float); memory only then
    p_.xr.assign(p_.x.begin(), p_.x.begin() + static_cast<std::ptrdiff_t>(p_.n_owned));
    p_.yr.assign(p_.y.begin(), p_.y.begin() + static_cast<std::ptrdiff_t>(p_.n_owned));
    p_.zr.assign(p_.z.begin(), p_.z.begin() + static_cast<std::ptrdiff_t>(p_.n_owned));
  }
  rebuild_step_ = step_;
  bond_broke_ = false;
  ++rebuilds_;
  if (std::getenv("BASALT_DEBUG_REBUILD"))
    fmt::print(stderr, "rank {} rebuild at step {} owned {} ghosts {} bonds {} (both owned {}) pairs {}+{}\n",
               comm().rank(), step_, p_.n_owned, p_.n_ghost(), bonds_.size(), bonds_.n_both_owned,
               forces_.own_pairs().pairs(), forces_.ghost_pairs().pairs());
  times_.neighbor += sw.lap();
}

#define BASALT_INSTANTIATE(R)                                              \
  template std::optional<std::string> Simulation<R>::check_finite() const; \
  template void Simulation<R>::spatial_sort();                             \
  template std::vector<std::uint32_t> Simulation<R>::resolve_bonds();      \
  template void Simulation<R>::rebuild();
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
