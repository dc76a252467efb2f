// Continuing a run from a checkpoint: the same decomposition (box, ghost width and contact cut-off
// stored with the checkpoint), particles with their velocities and exact inverse masses, bonds with
// their rest lengths, the clock. The first rebuild is canonical, as the uninterrupted run's rebuild
// at the checkpoint step was, so on the same ranks both runs continue bit for bit.
#include <fmt/format.h>

#include <cmath>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
Simulation<Real>::Simulation(const Scene& scene, const io::Checkpoint& c, const RestartLayout& layout,
                             MPI_Comm comm, const RunOptions& options)
    : scene_(scene),
      options_(options),
      bond_driver_(scene.bonds),
      pair_driver_(scene.contacts),
      wall_driver_(scene.walls) {
  if (c.size() == 0) throw InputError("the checkpoint has no particles");
  if (scene.bonds.size() > 254) throw InputError("interactions: at most 254 bond groups");
  if (c.dt != scene.dt)
    throw InputError(
        fmt::format("the checkpoint was written with dt = {}, the scene has run.dt = {}", c.dt, scene.dt));
  const bool se = scene.integrator == Integrator::symplectic_euler;
  kick1_ = Real(se ? scene.dt : scene.dt / 2);
  kick2_ = Real(se ? 0.0 : scene.dt / 2);
  rebuild_limit2_ = 0.25 * scene.skin * scene.skin;
  check_stability(c.geometry);
  distribute_checkpoint(c, layout, comm);
  // Walls where the uninterrupted run had them at this step's rebuild (step() moves them first).
  if (!wall_driver_.empty()) wall_driver_.move_to(double(step_) * scene.dt);
  canonical_ = true;
  rebuild();
  const auto pe = compute_forces<true>();
  energy0_ = total_energy(pe);
}

template <class Real>
void Simulation<Real>::distribute_checkpoint(const io::Checkpoint& c, const RestartLayout& layout,
                                             MPI_Comm comm) {
  const auto& g = c.geometry;
  dec_ = std::make_unique<Decomposition>(Comm(comm), options_.dims, layout.box_min, layout.box_max);
  halo_ = std::make_unique<Halo<Real>>(*dec_);
  n_global_ = static_cast<std::int64_t>(g.size());
  ids_.configure(g.id.front(), g.id.back(), g.size());
  ghost_width_ = layout.ghost_width;
  contact_cutoff_ = layout.contact_cutoff;
  if (dec_->min_interior_width() < ghost_width_)
    throw InputError(fmt::format(
        "too many ranks for this geometry: a rank's region would be {:.4g} wide, less than the ghost width "
        "{:.4g} (longest interaction + skin); use fewer ranks or other --dims (now {}x{}x{})",
        dec_->min_interior_width(), ghost_width_, dec_->dims()[0], dec_->dims()[1], dec_->dims()[2]));
  std::vector<char> owned(g.size(), 0);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const auto& x = g.position[i];
    if (!dec_->owns(x[0], x[1], x[2])) continue;
    owned[i] = 1;
    const double im = c.inv_mass.empty() ? 1.0 / g.mass[i] : c.inv_mass[i];
    const auto& v = c.velocity[i];
    p_.push_owned(g.id[i], Real(x[0]), Real(x[1]), Real(x[2]), Real(g.radius[i]), g.tag[i], Real(im),
                  Real(v[0]), Real(v[1]), Real(v[2]));
  }
  for (std::size_t k = 0; k < g.bonds.size(); ++k) {
    const auto& b = g.bonds[k];
    const auto ia = static_cast<std::size_t>(g.index_of(b.a)), ib = static_cast<std::size_t>(g.index_of(b.b));
    if (c.bond_broken[k]) {
      // Kept on record (once, by the rank owning the lower id) so later checkpoints still list it.
      const std::size_t lower = b.a < b.b ? ia : ib;
      if (owned[lower]) {
        const auto& pa = g.position[ia];
        const auto& pb = g.position[ib];
        const double len = std::sqrt((pa[0] - pb[0]) * (pa[0] - pb[0]) + (pa[1] - pb[1]) * (pa[1] - pb[1]) +
                                     (pa[2] - pb[2]) * (pa[2] - pb[2]));
        broken_.push_back({b.a, b.b, len, c.bond_rest_length[k]});
      }
      continue;
    }
    if (!owned[ia] && !owned[ib]) continue;
    if (b.tag < 0 || static_cast<std::size_t>(b.tag) >= scene_.bonds.size())
      throw InputError(
          fmt::format("the checkpoint's bond {}-{} belongs to interaction group {}, but the scene has "
                      "{} bond group(s)",
                      b.a, b.b, b.tag, scene_.bonds.size()));
    bonds_.push(b.a, b.b, Real(c.bond_rest_length[k]), static_cast<std::uint8_t>(b.tag));
  }
  step_ = c.step;
  time_ = c.time;
}

#define BASALT_INSTANTIATE(R)                                                                             \
  template Simulation<R>::Simulation(const Scene&, const io::Checkpoint&, const RestartLayout&, MPI_Comm, \
                                     const RunOptions&);                                                  \
  template void Simulation<R>::distribute_checkpoint(const io::Checkpoint&, const RestartLayout&, MPI_Comm);
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
