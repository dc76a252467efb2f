// Particles entering and leaving the run (core/particle_flow.hpp): the queue, the candidates' choice and the
// exchange at a rebuild.
#include "basalt/solver/core/particle_flow.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/core/sphere_mass.hpp"
#include "basalt/solver/neighbor/cell_grid.hpp"

namespace basalt::solver {

template <class Real>
void ParticleFlow<Real>::include(const Scene& scene, GeometryExtent& e) {
  // The lists' reach and the decomposition's box cover the particles to come.
  for (const auto& s : scene.inserts) {
    e.rmax = std::max(e.rmax, s.rmax);
    const auto b = s.region.bounds();
    for (std::size_t d = 0; d < 3; ++d) {
      e.lo[d] = std::min(e.lo[d], b[0][d]);
      e.hi[d] = std::max(e.hi[d], b[1][d]);
    }
  }
  rmax_ = e.rmax;
  next_id_ = e.last_id + 1;
}

template <class Real>
void ParticleFlow<Real>::restore(const Scene& scene, const std::map<std::string, std::string>& attributes,
                                 std::int64_t last_id, double rmax) {
  rmax_ = rmax;
  for (const auto& s : scene.inserts) rmax_ = std::max(rmax_, s.rmax);
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
bool ParticleFlow<Real>::queue(const Scene& scene, std::int64_t s) {
  for (const auto& i : scene.inserts)
    if (i.due(s)) queue_.inserts.push_back(i);
  for (const auto& d : scene.deletes)
    if (d.due(s)) queue_.deletes.push_back(d);
  return !queue_.inserts.empty() || !queue_.deletes.empty();
}

template <class Real>
void ParticleFlow<Real>::check_insert(const InsertSpec& s, double dt, double m_min, double dt_critical,
                                      bool forced) const {
  if (s.rmax > rmax_ * (1 + 1e-12))
    throw InputError(
        fmt::format("insert \"{}\": radius {} exceeds the largest radius {} the run's lists reach (the "
                    "geometry's and the "
                    "scene's [[insert]] radii): declare the largest radius in an [[insert]] of the scene",
                    s.name, s.rmax, rmax_));
  const double m = sphere_mass(s.density, s.rmin);
  if (m < m_min * (1 - 1e-12) && dt_critical > 0 && !forced) {
    // The lightest newcomer's contacts: the critical step scales with sqrt(m).
    const double limit = dt_critical * std::sqrt(m / m_min);
    if (dt > limit)
      throw InputError(fmt::format(
          "insert \"{}\": particles of radius {} (mass {:.4g}) are lighter than the run's lightest ({:.4g}): "
          "their contacts need dt below {:.4g}, the run has dt = {}; declare them in an [[insert]] of the "
          "scene (the critical step then counts them), or force with run.force_dt",
          s.name, s.rmin, m, m_min, limit, dt));
  }
  for (const double v : s.velocity)
    if (!std::isfinite(v))
      throw InputError(fmt::format("insert \"{}\": the velocity must be finite", s.name));
}

template <class Real>
void ParticleFlow<Real>::plan_arrivals(const Particles<Real>& p, const Decomposition& dec,
                                       std::int64_t step) {
  // Before the ghosts go: the owner of each candidate's place checks it against its owned particles and
  // ghosts (every particle within reach of its region), which are where they were at the last step. The
  // candidates go in batches of twice the particles still asked for, so that a region with room checks
  // few more than it takes (each batch: one small reduction).
  const std::size_t n = p.size();
  CellGrid grid;
  if (n > 0) grid.build(p.x, p.y, p.z, n, 2 * rmax_);
  const auto& start = grid.start();
  const auto& order = grid.order();
  const auto& dims = grid.dims();
  const auto blocked_here = [&](const NewParticle& c) {
    if (n == 0 || !dec.owns(c.x[0], c.x[1], c.x[2])) return false;
    const double reach = c.radius + rmax_;
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
            const double dx = c.x[0] - double(p.x[j]), dy = c.x[1] - double(p.y[j]),
                         dz = c.x[2] - double(p.z[j]), rs = c.radius + double(p.radius[j]);
            if (dx * dx + dy * dy + dz * dz < rs * rs) return true;
          }
        }
    return false;
  };
  const bool parallel = dec.comm().size() > 1;
  CandidatePicker picker(2 * rmax_);
  for (const auto& a : queue_.arriving) picker.add(a);
  for (const auto& s : queue_.inserts) {
    const auto cands = insertion_candidates(s, step);
    std::int64_t taken = 0;
    std::vector<double> blocked;
    for (std::size_t b0 = 0; b0 < cands.size() && taken < s.count;) {
      const std::size_t b1 = std::min(
          cands.size(), b0 + static_cast<std::size_t>(std::max<std::int64_t>(64, 2 * (s.count - taken))));
      blocked.assign(b1 - b0, 0.0);
      for (std::size_t k = b0; k < b1; ++k) blocked[k - b0] = blocked_here(cands[k]) ? 1 : 0;
      if (parallel) dec.comm().sum_all(blocked);
      for (std::size_t k = b0; k < b1 && taken < s.count; ++k) {
        if (blocked[k - b0] != 0 || !picker.try_take(cands[k])) continue;
        auto c = cands[k];
        c.id = next_id_++;
        ids_issued_ = true;
        queue_.arriving.push_back(c);
        ++taken;
      }
      b0 = b1;
    }
  }
}

template <class Real>
void ParticleFlow<Real>::exchange(Particles<Real>& p, Bonds<Real>& bonds, const Decomposition& dec) {
  // After the ghosts went, before migration: the owned particles of the deletion regions leave (with their
  // bonds, on every rank), the chosen newcomers whose place this rank owns arrive; migration then takes
  // every particle to the rank owning its place.
  std::vector<std::int64_t> gone;
  for (const auto& d : queue_.deletes)
    for (std::size_t i = p.n_owned; i-- > 0;) {
      if (!d.tags.empty() && std::find(d.tags.begin(), d.tags.end(), p.tag[i]) == d.tags.end()) continue;
      if (!d.region.contains({double(p.x[i]), double(p.y[i]), double(p.z[i])})) continue;
      gone.push_back(p.id[i]);
      p.swap_remove_owned(i);
    }
  const bool parallel = dec.comm().size() > 1;
  std::vector<std::int64_t> all_gone = parallel ? dec.comm().all_gather_ids(gone) : gone;
  std::sort(all_gone.begin(), all_gone.end());
  if (!all_gone.empty() && bonds.size() > 0) {
    std::vector<std::size_t> cut;
    for (std::size_t k = 0; k < bonds.size(); ++k)
      if (std::binary_search(all_gone.begin(), all_gone.end(), bonds.a[k]) ||
          std::binary_search(all_gone.begin(), all_gone.end(), bonds.b[k]))
        cut.push_back(k);
    bonds.erase(cut);
    bonds.parted.clear();  // (their local ends are stale: the lists are rebuilt from the bonds below)
  }
  for (const auto& c : queue_.arriving) {
    if (!dec.owns(c.x[0], c.x[1], c.x[2])) continue;
    p.push_owned(c.id, Real(c.x[0]), Real(c.x[1]), Real(c.x[2]), Real(c.radius), c.tag, Real(c.inv_mass),
                 Real(c.v[0]), Real(c.v[1]), Real(c.v[2]));
  }
  last_ = {static_cast<std::int64_t>(queue_.arriving.size()), static_cast<std::int64_t>(all_gone.size())};
  totals_[0] += last_[0];
  totals_[1] += last_[1];
  changed_ = changed_ || last_[0] > 0 || last_[1] > 0;
  queue_ = {};
}

template class ParticleFlow<double>;
template class ParticleFlow<float>;

}  // namespace basalt::solver
