// The last step's forces and torques through a checkpoint, for velocity Verlet's first half-kick.
// A step kicks by F_n dt/2, drifts, computes F_{n+1} and kicks by F_{n+1} dt/2; a model reading
// velocities (damping, dashpots) computes F_{n+1} from the half-step velocities v_{n+1/2}. A checkpoint
// holds v_{n+1}, so the force a restart computes at its start differs from F_{n+1} in the last bits
// (symplectic Euler has no second kick: there the velocities are those the forces saw, and a restart
// recomputes them exactly). Checkpoints of such scenes therefore store the forces and torques, and a
// restart takes them for its first kick: the continuation is bit for bit (issue #11).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdio>

#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
bool Simulation<Real>::checkpoints_forces() const {
  return kick2_ != Real(0) && forces_.reads_velocity();
}

template <class Real>
void Simulation<Real>::restore_kick_forces(const io::Checkpoint& c) {
  if (!checkpoints_forces()) return;
  const std::size_t n = p_.with_rotation ? 6 : 3;
  std::array<const std::vector<double>*, 6> from{};
  for (std::size_t k = 0; k < n; ++k) {
    const auto it = std::find_if(c.particle_fields.begin(), c.particle_fields.end(),
                                 [&](const auto& f) { return f.first == kick_force_fields[k]; });
    if (it == c.particle_fields.end()) {
      if (comm().rank() == 0)
        fmt::print(
            stderr,
            "basalt-run: warning: the checkpoint has no /particles/{} (written by an older basalt-run or "
            "with another integrator): velocity Verlet's first half-kick takes forces recomputed from "
            "the checkpoint's velocities, not the half-step velocities the uninterrupted run computed "
            "them from, so the continuation agrees with it to rounding only\n",
            kick_force_fields[k]);
      return;
    }
    from[k] = &it->second;
  }
  const std::array<std::vector<Real>*, 6> to{&p_.fx, &p_.fy, &p_.fz, &p_.tx, &p_.ty, &p_.tz};
  const auto& g = c.geometry;
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    const auto gi = static_cast<std::size_t>(g.index_of(p_.id[i]));
    for (std::size_t k = 0; k < n; ++k) (*to[k])[i] = Real((*from[k])[gi]);
  }
}

template bool Simulation<double>::checkpoints_forces() const;
template bool Simulation<float>::checkpoints_forces() const;
template void Simulation<double>::restore_kick_forces(const io::Checkpoint&);
template void Simulation<float>::restore_kick_forces(const io::Checkpoint&);

}  // namespace basalt::solver
