// Neighbour-list rebuilds: the non-finite check, migration (with bonds and contact history), the
// canonical spatial sort, ghosts, bonds resolved to local indices in canonical order, then the
// force field's lists. Every rebuild is canonical: a restart replays one bit for bit.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <type_traits>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
std::optional<std::string> Simulation<Real>::check_finite() const {
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    const bool ok = std::isfinite(p_.x[i]) && std::isfinite(p_.y[i]) && std::isfinite(p_.z[i]) &&
                    std::isfinite(p_.vx[i]) && std::isfinite(p_.vy[i]) && std::isfinite(p_.vz[i]) &&
                    std::isfinite(p_.fx[i]) && std::isfinite(p_.fy[i]) && std::isfinite(p_.fz[i]) &&
                    (!p_.with_rotation ||
                     (std::isfinite(p_.wx[i]) && std::isfinite(p_.wy[i]) && std::isfinite(p_.wz[i])));
    if (!ok)
      return fmt::format(
          "step {}: particle id {} went non-finite: position ({}, {}, {}), velocity ({}, {}, {}), force ({}, "
          "{}, "
          "{}); dt = {} is {:.3g} x the critical time step",
          clock_.step(), p_.id[i], p_.x[i], p_.y[i], p_.z[i], p_.vx[i], p_.vy[i], p_.vz[i], p_.fx[i],
          p_.fy[i], p_.fz[i], scene_.dt, stability_.fraction);
  }
  return std::nullopt;
}

template <class Real>
void Simulation<Real>::spatial_sort() {
  // Owned particles in cell order: neighbours in space become neighbours in memory. Within a cell
  // by id, so the order is a function of the owned (id, position) set alone, never of the order
  // migration or a restart left them in: every rebuild is canonical (a restart replays one bit for
  // bit, docs/ARCHITECTURE.md). A cell holds a few particles: sorting them costs little.
  CellGrid grid;  // freed before the contact lists build theirs (peak memory)
  grid.build(p_.x, p_.y, p_.z, p_.n_owned, contact_cutoff_);
  const auto& order = grid.order();
  const auto& start = grid.start();
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
          clock_.step(), bonds_.a[k], bonds_.b[k], ghost_width_, ia < 0 ? bonds_.a[k] : bonds_.b[k],
          comm().rank());
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
void Simulation<Real>::set_skin_reference() {
  const auto& o = p_.skin_origin = skin_origin(dec_->box_min(), dec_->box_max());
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    p_.x0[i] = float(double(p_.x[i]) - o[0]);
    p_.y0[i] = float(double(p_.y[i]) - o[1]);
    p_.z0[i] = float(double(p_.z[i]) - o[2]);
  }
}

template <class Real>
void Simulation<Real>::rebuild() {
  // The phases as basalt-run reports them: the checks and the histories' save are the rebuild's own work
  // (neighbour search), the agreement, migration and balancing are communication.
  Stopwatch sw;
  auto error = check_finite();
  times_.neighbor += sw.lap();
  const bool parallel = comm().size() > 1;
  if (parallel) error = comm().agree_error(error);
  if (error) stop(*error);
  if (parallel && scene_.balance == "pairs" && !balancer_.paused() && schedule_.count() > 0)
    balancer_.weigh_pairs(balance_run());
  times_.communication += sw.lap();
  forces_.save_history(p_);  // before the ghosts (and the pairs' ids) go
  const bool flow = flow_.pending();
  if (flow) flow_.plan_arrivals(p_, *dec_, clock_.step());  // (reads the ghosts)
  p_.drop_ghosts();
  if (flow) exchange_flow();
  times_.neighbor += sw.lap();
  if (parallel) {
    error = halo_->migrate(p_, bonds_, forces_.pending_history(), schedule_.take_far_moves());
    error = comm().agree_error(error);
    if (error) stop(*error);
    const long long total = comm().sum(static_cast<long long>(p_.n_owned));
    if (total != n_global_)
      stop(fmt::format("step {}: {} particles on the ranks, {} expected: particles were lost", clock_.step(),
                       total, n_global_));
    if (scene_.balance != "none" && !balancer_.paused())
      if (auto balance_error = balancer_.at_rebuild(balance_run())) stop(*balance_error);
  }
  times_.communication += sw.lap();
  spatial_sort();
  times_.neighbor += sw.lap();
  if (parallel) halo_->build_ghosts(p_, ghost_width_);
  times_.communication += sw.lap();
  const auto bond_bucket_end = resolve_bonds();
  forces_.rebuild_lists(p_, bond_bucket_end, bonds_, scene_.skin, contact_cutoff_);
  set_skin_reference();
  if (p_.with_exact_rebuild) {  // exact copies for the checkpoints (x0 is float); memory only then
    p_.xr.assign(p_.x.begin(), p_.x.begin() + static_cast<std::ptrdiff_t>(p_.n_owned));
    p_.yr.assign(p_.y.begin(), p_.y.begin() + static_cast<std::ptrdiff_t>(p_.n_owned));
    p_.zr.assign(p_.z.begin(), p_.z.begin() + static_cast<std::ptrdiff_t>(p_.n_owned));
  }
  fixed_.find(p_, scene_.fixed_tags);
  schedule_.rebuilt(clock_.step());
  check_rebuild();
  if (std::getenv("BASALT_DEBUG_REBUILD"))
    fmt::print(stderr, "rank {} rebuild at step {} owned {} ghosts {} bonds {} (both owned {}) pairs {}+{}\n",
               comm().rank(), clock_.step(), p_.n_owned, p_.n_ghost(), bonds_.size(), bonds_.n_both_owned,
               forces_.own_pairs().pairs(), forces_.ghost_pairs().pairs());
  times_.neighbor += sw.lap();
}

template <class Real>
void Simulation<Real>::check_rebuild() {
  const typename RebuildChecks<Real>::State state{
      p_, bonds_, forces_, comm(), clock_.step(), stability_.rmin, precision_name()};
  // Only scenes with a closed-form collision (hertz_mindlin) look at collisions.
  if (auto error = checks_.impacts(state, scene_.dt, scene_.fixed_tags, scene_.force_dt || options_.force_dt,
                                   stability_.dt_critical))
    stop(*error);
  if constexpr (std::is_same_v<Real, float>)
    checks_.far_positions(state);
  else
    checks_.lost_strain(state);  // (float's and mixed's own rounding of the wave's strains is ~1e-3 of them
                                 // at the origin)
}

template <class Real>
void Simulation<Real>::check_start(bool fresh) {
  std::optional<std::string> error;
  double worst = 0;  // deepest overlap relative to the smaller radius (unbonded pairs, walls)
  std::string where;
  const auto pair = [&](std::size_t i, std::size_t j, bool bonded) {
    const double dx = double(p_.x[i] - p_.x[j]), dy = double(p_.y[i] - p_.y[j]),
                 dz = double(p_.z[i] - p_.z[j]);
    const double r = std::sqrt(dx * dx + dy * dy + dz * dz), ri = double(p_.radius[i]),
                 rj = double(p_.radius[j]);
    if (!(r > 1e-9 * (ri + rj))) {
      if (!error)
        error = fmt::format(
            "particles id {} and id {} are {:.3g} apart (radii {:.6g} and {:.6g}): coincident particles (a "
            "particle "
            "doubled in the geometry or checkpoint?) would make the first force infinite",
            p_.id[i], p_.id[j], r, ri, rj);
      return;
    }
    const double overlap = (ri + rj - r) / std::min(ri, rj);
    if (!bonded && overlap > worst) {
      worst = overlap;
      where = fmt::format(
          "particles id {} and id {} overlap by {:.3g} of the smaller radius ({:.6g} apart, radii "
          "{:.6g} and {:.6g})",
          p_.id[i], p_.id[j], overlap, r, ri, rj);
    }
  };
  for (const PairList* list : {&forces_.own_pairs(), &forces_.ghost_pairs()})
    for (std::size_t i = 0; i + 1 < list->offset.size(); ++i)
      for (auto k = list->offset[i]; k < list->offset[i + 1]; ++k)
        if (!list->is_bonded(k)) pair(i, static_cast<std::size_t>(list->neigh[k]), false);
  for (std::size_t k = 0; k < bonds_.size(); ++k)
    pair(static_cast<std::size_t>(bonds_.ia[k]), static_cast<std::size_t>(bonds_.ib[k]), true);
  const auto& walls = forces_.walls();
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const auto& n = walls.spec(w).normal;
    const auto& at = walls.point(w);
    for (const auto i : walls.candidates(w)) {
      if (walls.spec(w).bonds(p_.tag[i])) continue;  // tied to the wall: its spring, not an overlap
      const double d = (double(p_.x[i]) - at[0]) * n[0] + (double(p_.y[i]) - at[1]) * n[1] +
                       (double(p_.z[i]) - at[2]) * n[2];
      const double overlap = (double(p_.radius[i]) - d) / double(p_.radius[i]);
      if (overlap > worst) {
        worst = overlap;
        where = fmt::format(
            "particle id {} overlaps wall \"{}\" by {:.3g} of its radius (centre {:.6g} from the plane)",
            p_.id[i], walls.spec(w).name, overlap, d);
      }
    }
  }
  // Mesh walls ([[mesh_walls]]): the deepest of a particle's contacts with the mesh's faces, edges and
  // vertices (a centre on the surface overlaps by its whole radius).
  std::vector<MeshContact> contacts;
  for (std::size_t w = 0; w < walls.meshes(); ++w)
    for (const auto i : walls.mesh_candidates(w)) {
      const auto k = static_cast<std::size_t>(i);
      contacts.clear();
      walls.mesh(w).contacts({double(p_.x[k]), double(p_.y[k]), double(p_.z[k])}, double(p_.radius[k]),
                             contacts);
      for (const auto& c : contacts) {
        const double overlap = c.overlap / double(p_.radius[k]);
        if (overlap > worst) {
          worst = overlap;
          where = fmt::format(
              "particle id {} overlaps mesh wall \"{}\" by {:.3g} of its radius (centre {:.6g} from the mesh "
              "at ({:.6g}, {:.6g}, {:.6g}))",
              p_.id[k], walls.mesh_spec(w).name, overlap, c.distance, c.point[0], c.point[1], c.point[2]);
        }
      }
    }
  if (comm().size() > 1) error = comm().agree_error(error);
  if (error) throw InputError(*error);
  const auto [top, who] = comm().max_loc(worst);
  if (top <= 0.1) return;
  const std::string deepest = comm().broadcast(where, who);
  if (fresh && top > 0.5 && !(scene_.force_overlap || options_.force_overlap))
    throw InputError(
        fmt::format("the geometry starts with deep overlaps: {}; the repulsion would launch them at "
                    "speeds far beyond the scene's. Fix the geometry, or set run.force_overlap = true "
                    "/ --force-overlap to start anyway",
                    deepest));
  if (comm().rank() == 0)
    fmt::print(stderr, "basalt-run: warning: the deepest overlap at {}: {}\n", fresh ? "start" : "restart",
               deepest);
}

#define BASALT_INSTANTIATE(R)                                              \
  template std::optional<std::string> Simulation<R>::check_finite() const; \
  template void Simulation<R>::spatial_sort();                             \
  template std::vector<std::uint32_t> Simulation<R>::resolve_bonds();      \
  template void Simulation<R>::rebuild();                                  \
  template void Simulation<R>::set_skin_reference();                       \
  template void Simulation<R>::check_rebuild();                            \
  template void Simulation<R>::check_start(bool);
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
