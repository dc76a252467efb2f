// The last step's forces and torques through a checkpoint: a restart's first kick takes them instead of
// forces it recomputes. A recomputation need not give the uninterrupted run's bits:
// - velocity Verlet kicks by F_n dt/2, drifts, computes F_{n+1} and kicks by F_{n+1} dt/2; a model
//   reading velocities (damping, dashpots) computes F_{n+1} from the half-step velocities v_{n+1/2},
//   while a checkpoint holds v_{n+1};
// - a step computes forces through other instantiations of the force loops than a restart's start does
//   (Advance: contact history moves on), and with -march=native the compiler contracts a * b + c into
//   fused multiply-adds differently in each: forces from the same positions, velocities and history
//   differed in the last bit (scenes/granular-esys.toml, symplectic Euler: 35 of 2,884 particles at
//   step 500; with -ffp-contract=off, none).
// So every checkpoint stores them (/particles/force_x ... torque_z) and the restart, after its start's
// force computation (which the energy ledger still uses), puts them back: bit for bit (issue #11).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <vector>

#include "basalt/solver/parallel/checkpoint_loader.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
void Simulation<Real>::restore_kick_forces(const io::Checkpoint& c) {
  const std::size_t n = p_.with_rotation ? 6 : 3;
  std::array<const std::vector<double>*, 6> from{};
  for (std::size_t k = 0; k < n; ++k) {
    const auto it = std::find_if(c.particle_fields.begin(), c.particle_fields.end(),
                                 [&](const auto& f) { return f.first == kick_force_fields[k]; });
    if (it == c.particle_fields.end()) {
      if (comm().rank() == 0)
        fmt::print(
            stderr,
            "basalt-run: warning: the checkpoint has no /particles/{} (written by an older basalt-run): "
            "the first step kicks with forces recomputed at the restart, which can differ from the "
            "uninterrupted run's in the last bits (velocity Verlet computed those from half-step "
            "velocities), so the continuation agrees with it to rounding only\n",
            kick_force_fields[k]);
      return;
    }
    from[k] = &it->second;
  }
  const std::array<std::vector<Real>*, 6> to{&p_.fx, &p_.fy, &p_.fz, &p_.tx, &p_.ty, &p_.tz};
  const auto& g = c.geometry;
  // A sliced restart on another rank grid: the replayed rebuild's re-balance can move particles to a rank
  // that did not read their rows; their values come from the ranks that did (as their positions do).
  std::vector<std::int64_t> moved;
  for (std::size_t i = 0; i < p_.n_owned; ++i)
    if (g.index_of(p_.id[i]) < 0) moved.push_back(p_.id[i]);
  std::array<std::vector<io::Vec3>, 2> moved_values;  // forces, torques
  if (comm().size() > 1 && comm().sum(static_cast<long long>(moved.size())) > 0) {
    std::sort(moved.begin(), moved.end());
    for (std::size_t part = 0; part < n / 3; ++part) {
      std::vector<io::Vec3> held(g.size());
      for (std::size_t i = 0; i < g.size(); ++i)
        held[i] = {(*from[3 * part])[i], (*from[3 * part + 1])[i], (*from[3 * part + 2])[i]};
      moved_values[part] = positions_of(comm(), moved, g.id, held);
    }
  }
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    const auto gi = g.index_of(p_.id[i]);
    if (gi >= 0) {
      for (std::size_t k = 0; k < n; ++k) (*to[k])[i] = Real((*from[k])[static_cast<std::size_t>(gi)]);
      continue;
    }
    const auto m =
        static_cast<std::size_t>(std::lower_bound(moved.begin(), moved.end(), p_.id[i]) - moved.begin());
    for (std::size_t k = 0; k < n; ++k) (*to[k])[i] = Real(moved_values[k / 3][m][k % 3]);
  }
}

template void Simulation<double>::restore_kick_forces(const io::Checkpoint&);
template void Simulation<float>::restore_kick_forces(const io::Checkpoint&);

}  // namespace basalt::solver
