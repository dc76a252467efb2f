// Particles entering and leaving the run, the Simulation's side (core/particle_flow.hpp holds the queue,
// the choice of the inserted particles and the exchange; docs/scenes.md "Insertion and deletion"): the
// stability estimate's share of the scene's inserts, the count and id map after an exchange, and the calls
// between steps (insert_particles, remove_particles: Python), which rebuild at once.
#include <algorithm>
#include <utility>

#include "basalt/solver/core/sphere_mass.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

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
void Simulation<Real>::exchange_flow() {
  flow_.exchange(p_, bonds_, *dec_);
  const auto& last = flow_.last();
  n_global_ += last[0] - last[1];
  if (last[0] > 0) ids_.grow(flow_.next_id() - 1, static_cast<std::size_t>(n_global_));
}

template <class Real>
std::int64_t Simulation<Real>::insert_particles(InsertSpec spec) {
  flow_.check_insert(spec, scene_.dt, stability_.m_min, stability_.dt_critical,
                     scene_.force_dt || options_.force_dt);
  if (mixed_) spec.region.shift(origin_);
  flow_.queue(std::move(spec));
  flow_now();
  return flow_.last()[0];
}

template <class Real>
std::int64_t Simulation<Real>::remove_particles(DeleteSpec spec) {
  std::vector<DeleteSpec> specs;
  specs.push_back(std::move(spec));
  return remove_particles(std::move(specs));
}

template <class Real>
std::int64_t Simulation<Real>::remove_particles(std::vector<DeleteSpec> specs) {
  for (auto& spec : specs) {
    if (mixed_) spec.region.shift(origin_);
    flow_.queue(std::move(spec));
  }
  flow_now();
  return flow_.last()[1];
}

template <class Real>
void Simulation<Real>::flow_now() {
  settle_kick();
  integrator_.forget_energy();
  rebuild();
  const auto& pe = compute_forces<true>();
  if (flow_.changed()) rebase_ledger(pe);
}

#define BASALT_INSTANTIATE(R)                                                     \
  template void Simulation<R>::include_flow(GeometrySummary&) const;              \
  template void Simulation<R>::exchange_flow();                                   \
  template std::int64_t Simulation<R>::insert_particles(InsertSpec);              \
  template std::int64_t Simulation<R>::remove_particles(DeleteSpec);              \
  template std::int64_t Simulation<R>::remove_particles(std::vector<DeleteSpec>); \
  template void Simulation<R>::flow_now();
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
