// Particles entering and leaving the run (scene/flow_spec.hpp, docs/scenes.md "Insertion and deletion"):
// both happen at a rebuild, as a step begins (the scene's [[insert]] and [[delete]] events) or when asked
// between steps (insert_particles, remove_particles: Python). Insertion draws its candidates alike on every
// rank (core/particle_source.hpp), lets the rank owning each candidate's place say whether an existing
// particle (owned or ghost) blocks it, agrees on that, and takes the same candidates everywhere with ids
// from one counter (next_id_, kept in checkpoints): ids stay unique and the inserted set does not depend on
// the ranks. Deletion removes the owned particles of the region and, on every rank, the bonds to them.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/core/particle_source.hpp"
#include "basalt/solver/core/sphere_mass.hpp"
#include "basalt/solver/neighbor/cell_grid.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
void Simulation<Real>::include_flow(GeometryExtent& e) {
  // The lists' reach and the decomposition's box cover the particles to come.
  for (const auto& s : scene_.inserts) {
    e.rmax = std::max(e.rmax, s.rmax);
    const auto b = s.region.bounds();
    for (std::size_t d = 0; d < 3; ++d) {
      e.lo[d] = std::min(e.lo[d], b[0][d]);
      e.hi[d] = std::max(e.hi[d], b[1][d]);
    }
  }
  rmax_run_ = e.rmax;
  next_id_ = e.last_id + 1;
}

template <class Real>
void Simulation<Real>::include_flow(GeometrySummary& s) const {
  // A contact an inserted particle makes later is one of the stability estimate's future contacts.
  for (const auto& i : scene_.inserts) {
    s.rmin = std::min(s.rmin, i.rmin);
    s.rmax = std::max(s.rmax, i.rmax);
    s.m_min_pow = std::min(s.m_min_pow, sphere_mass(i.density, i.rmin));
  }
}

template <class Real>
void Simulation<Real>::restore_flow(const std::map<std::string, std::string>& attributes,
                                    std::int64_t last_id, double rmax) {
  rmax_run_ = rmax;
  for (const auto& s : scene_.inserts) rmax_run_ = std::max(rmax_run_, s.rmax);
  next_id_ = last_id + 1;
  if (const auto it = attributes.find("next_particle_id"); it != attributes.end()) {
    try {
      next_id_ = std::max(next_id_, static_cast<std::int64_t>(std::stoll(it->second)));
    } catch (const std::exception&) {
      throw InputError(
          fmt::format("the checkpoint's attribute next_particle_id = \"{}\" is not an integer", it->second));
    }
    ids_issued_ = true;
  }
}

template <class Real>
bool Simulation<Real>::queue_flow(std::int64_t s) {
  for (const auto& i : scene_.inserts)
    if (i.due(s)) flow_.inserts.push_back(i);
  for (const auto& d : scene_.deletes)
    if (d.due(s)) flow_.deletes.push_back(d);
  return !flow_.inserts.empty() || !flow_.deletes.empty();
}

template <class Real>
void Simulation<Real>::check_insert(const InsertSpec& s) const {
  if (s.rmax > rmax_run_ * (1 + 1e-12))
    throw InputError(
        fmt::format("insert \"{}\": radius {} exceeds the largest radius {} the run's lists reach (the "
                    "geometry's and the "
                    "scene's [[insert]] radii): declare the largest radius in an [[insert]] of the scene",
                    s.name, s.rmax, rmax_run_));
  const double m = sphere_mass(s.density, s.rmin);
  if (m < stability_.m_min * (1 - 1e-12) && stability_.dt_critical > 0 && !scene_.force_dt &&
      !options_.force_dt) {
    // The lightest newcomer's contacts: the critical step scales with sqrt(m).
    const double limit = stability_.dt_critical * std::sqrt(m / stability_.m_min);
    if (scene_.dt > limit)
      throw InputError(fmt::format(
          "insert \"{}\": particles of radius {} (mass {:.4g}) are lighter than the run's lightest ({:.4g}): "
          "their contacts need dt below {:.4g}, the run has dt = {}; declare them in an [[insert]] of the "
          "scene (the critical step then counts them), or force with run.force_dt",
          s.name, s.rmin, m, stability_.m_min, limit, scene_.dt));
  }
  for (const double v : s.velocity)
    if (!std::isfinite(v))
      throw InputError(fmt::format("insert \"{}\": the velocity must be finite", s.name));
}

template <class Real>
void Simulation<Real>::plan_arrivals() {
  // Before the ghosts go: the owner of each candidate's place checks it against its owned particles and
  // ghosts (every particle within reach of its region), which are where they were at the last step. The
  // candidates go in batches of twice the particles still asked for, so that a region with room checks
  // few more than it takes (each batch: one small reduction).
  const std::size_t n = p_.size();
  CellGrid grid;
  if (n > 0) grid.build(p_.x, p_.y, p_.z, n, 2 * rmax_run_);
  const auto& start = grid.start();
  const auto& order = grid.order();
  const auto& dims = grid.dims();
  const auto blocked_here = [&](const NewParticle& c) {
    if (n == 0 || !dec_->owns(c.x[0], c.x[1], c.x[2])) return false;
    const double reach = c.radius + rmax_run_;
    std::array<std::int64_t, 3> lo{}, hi{};
    for (int d = 0; d < 3; ++d) {
      lo[d] = grid.coord(d, c.x[static_cast<std::size_t>(d)] - reach);
      hi[d] = grid.coord(d, c.x[static_cast<std::size_t>(d)] + reach);
    }
    for (auto cz = lo[2]; cz <= hi[2]; ++cz)
      for (auto cy = lo[1]; cy <= hi[1]; ++cy)
        for (auto cx = lo[0]; cx <= hi[0]; ++cx) {
          const auto cell = static_cast<std::size_t>((cz * dims[1] + cy) * dims[0] + cx);
          for (auto e = start[cell]; e < start[cell + 1]; ++e) {
            const auto j = order[e];
            const double dx = c.x[0] - double(p_.x[j]), dy = c.x[1] - double(p_.y[j]),
                         dz = c.x[2] - double(p_.z[j]), rs = c.radius + double(p_.radius[j]);
            if (dx * dx + dy * dy + dz * dz < rs * rs) return true;
          }
        }
    return false;
  };
  const bool parallel = comm().size() > 1;
  CandidatePicker picker(2 * rmax_run_);
  for (const auto& a : flow_.arriving) picker.add(a);
  for (const auto& s : flow_.inserts) {
    const auto cands = insertion_candidates(s, step_);
    std::int64_t taken = 0;
    std::vector<double> blocked;
    for (std::size_t b0 = 0; b0 < cands.size() && taken < s.count;) {
      const std::size_t b1 = std::min(
          cands.size(), b0 + static_cast<std::size_t>(std::max<std::int64_t>(64, 2 * (s.count - taken))));
      blocked.assign(b1 - b0, 0.0);
      for (std::size_t k = b0; k < b1; ++k) blocked[k - b0] = blocked_here(cands[k]) ? 1 : 0;
      if (parallel) comm().sum_all(blocked);
      for (std::size_t k = b0; k < b1 && taken < s.count; ++k) {
        if (blocked[k - b0] != 0 || !picker.try_take(cands[k])) continue;
        auto c = cands[k];
        c.id = next_id_++;
        ids_issued_ = true;
        flow_.arriving.push_back(c);
        ++taken;
      }
      b0 = b1;
    }
  }
}

template <class Real>
void Simulation<Real>::exchange_flow() {
  // After the ghosts went, before migration: the owned particles of the deletion regions leave (with their
  // bonds, on every rank), the chosen newcomers whose place this rank owns arrive; migration then takes
  // every particle to the rank owning its place.
  std::vector<std::int64_t> gone;
  for (const auto& d : flow_.deletes)
    for (std::size_t i = p_.n_owned; i-- > 0;) {
      if (!d.tags.empty() && std::find(d.tags.begin(), d.tags.end(), p_.tag[i]) == d.tags.end()) continue;
      if (!d.region.contains({double(p_.x[i]), double(p_.y[i]), double(p_.z[i])})) continue;
      gone.push_back(p_.id[i]);
      p_.swap_remove_owned(i);
    }
  const bool parallel = comm().size() > 1;
  std::vector<std::int64_t> all_gone = parallel ? comm().all_gather_ids(gone) : gone;
  std::sort(all_gone.begin(), all_gone.end());
  if (!all_gone.empty() && bonds_.size() > 0) {
    std::vector<std::size_t> cut;
    for (std::size_t k = 0; k < bonds_.size(); ++k)
      if (std::binary_search(all_gone.begin(), all_gone.end(), bonds_.a[k]) ||
          std::binary_search(all_gone.begin(), all_gone.end(), bonds_.b[k]))
        cut.push_back(k);
    bonds_.erase(cut);
    bonds_.parted.clear();  // (their local ends are stale: the lists are rebuilt from the bonds below)
  }
  for (const auto& c : flow_.arriving) {
    if (!dec_->owns(c.x[0], c.x[1], c.x[2])) continue;
    p_.push_owned(c.id, Real(c.x[0]), Real(c.x[1]), Real(c.x[2]), Real(c.radius), c.tag, Real(c.inv_mass),
                  Real(c.v[0]), Real(c.v[1]), Real(c.v[2]));
  }
  last_flow_ = {static_cast<std::int64_t>(flow_.arriving.size()), static_cast<std::int64_t>(all_gone.size())};
  flow_totals_[0] += last_flow_[0];
  flow_totals_[1] += last_flow_[1];
  n_global_ += last_flow_[0] - last_flow_[1];
  if (last_flow_[0] > 0) ids_.grow(next_id_ - 1, static_cast<std::size_t>(n_global_));
  flow_changed_ = flow_changed_ || last_flow_[0] > 0 || last_flow_[1] > 0;
  flow_ = {};
}

template <class Real>
std::int64_t Simulation<Real>::insert_particles(InsertSpec spec) {
  check_insert(spec);
  if (mixed_) spec.region.shift(origin_);
  flow_.inserts.push_back(std::move(spec));
  flow_now();
  return last_flow_[0];
}

template <class Real>
std::int64_t Simulation<Real>::remove_particles(DeleteSpec spec) {
  if (mixed_) spec.region.shift(origin_);
  flow_.deletes.push_back(std::move(spec));
  flow_now();
  return last_flow_[1];
}

template <class Real>
void Simulation<Real>::flow_now() {
  settle_kick();
  integrator_.forget_energy();
  rebuild();
  const auto& pe = compute_forces<true>();
  if (flow_changed_) rebase_ledger(pe);
}

#define BASALT_INSTANTIATE(R)                                                                        \
  template void Simulation<R>::include_flow(GeometryExtent&);                                        \
  template void Simulation<R>::include_flow(GeometrySummary&) const;                                 \
  template bool Simulation<R>::queue_flow(std::int64_t);                                             \
  template void Simulation<R>::restore_flow(const std::map<std::string, std::string>&, std::int64_t, \
                                            double);                                                 \
  template void Simulation<R>::check_insert(const InsertSpec&) const;                                \
  template void Simulation<R>::plan_arrivals();                                                      \
  template void Simulation<R>::exchange_flow();                                                      \
  template std::int64_t Simulation<R>::insert_particles(InsertSpec);                                 \
  template std::int64_t Simulation<R>::remove_particles(DeleteSpec);                                 \
  template void Simulation<R>::flow_now();
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
