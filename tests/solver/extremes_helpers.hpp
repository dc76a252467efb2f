#pragma once
// Shared by the extremes tests (docs/stability.md, "Stability at the extremes"): the state of every
// particle gathered from all ranks by id, and a total energy.
#include <mpi.h>

#include <array>
#include <cstdint>
#include <vector>

#include "basalt/solver/simulation.hpp"

namespace basalt::test {

/// Every particle's position, velocity and force (double), indexed by id - first_id, on every rank.
struct GlobalState {
  std::vector<std::array<double, 3>> x, v, f;
  std::vector<int> seen;  ///< how many ranks own each id (1 when nothing is lost or doubled)
};

template <class Real>
GlobalState gather_state(const solver::Simulation<Real>& sim, std::int64_t first_id, std::size_t n) {
  const auto& p = sim.particles();
  std::vector<double> buf(10 * n, 0.0);
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const auto k = static_cast<std::size_t>(p.id[i] - first_id);
    if (k >= n) continue;
    double* b = &buf[10 * k];
    const double vals[10] = {
        double(p.x[i]),  double(p.y[i]),  double(p.z[i]),  double(p.vx[i]), double(p.vy[i]),
        double(p.vz[i]), double(p.fx[i]), double(p.fy[i]), double(p.fz[i]), 1.0};
    for (int c = 0; c < 10; ++c) b[c] += vals[c];
  }
  sim.comm().sum_all(buf);
  GlobalState s;
  s.x.resize(n);
  s.v.resize(n);
  s.f.resize(n);
  s.seen.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double* b = &buf[10 * k];
    s.x[k] = {b[0], b[1], b[2]};
    s.v[k] = {b[3], b[4], b[5]};
    s.f[k] = {b[6], b[7], b[8]};
    s.seen[k] = static_cast<int>(b[9]);
  }
  return s;
}

/// Collective: kinetic + bond + contact + wall energy.
template <class Real>
double total_energy(solver::Simulation<Real>& sim) {
  const auto e = sim.energies();
  return e[0] + e[1] + e[2] + e[3];
}

}  // namespace basalt::test
