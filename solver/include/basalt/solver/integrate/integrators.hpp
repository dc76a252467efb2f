#pragma once
// Time integration of owned particles, split into a kick (v += F/m h) and a drift (x += v h).
//   velocity Verlet:  kick(dt/2), drift(dt), forces, kick(dt/2)
//   symplectic Euler: kick(dt),   drift(dt), forces            (ESyS-Particle's scheme)
// drift() returns the largest squared displacement since the last rebuild (NaN/inf if any position
// went non-finite), which decides the next neighbour-list rebuild.
#include <cmath>
#include <limits>

#include "basalt/solver/core/particles.hpp"

namespace basalt::solver {

template <class Real>
void kick(Particles<Real>& p, Real h) {
  const std::size_t n = p.n_owned;
  Real* __restrict vx = p.vx.data();
  Real* __restrict vy = p.vy.data();
  Real* __restrict vz = p.vz.data();
  const Real* __restrict fx = p.fx.data();
  const Real* __restrict fy = p.fy.data();
  const Real* __restrict fz = p.fz.data();
  const Real* __restrict im = p.inv_mass.data();
  for (std::size_t i = 0; i < n; ++i) {
    const Real s = h * im[i];
    vx[i] += s * fx[i];
    vy[i] += s * fy[i];
    vz[i] += s * fz[i];
  }
}

template <class Real>
double drift(Particles<Real>& p, Real h) {
  const std::size_t n = p.n_owned;
  Real* __restrict x = p.x.data();
  Real* __restrict y = p.y.data();
  Real* __restrict z = p.z.data();
  const Real* __restrict vx = p.vx.data();
  const Real* __restrict vy = p.vy.data();
  const Real* __restrict vz = p.vz.data();
  const float* __restrict x0 = p.x0.data();
  const float* __restrict y0 = p.y0.data();
  const float* __restrict z0 = p.z0.data();
  Real m = 0;
  Real sum = 0;  // non-finite positions make the sum non-finite
  for (std::size_t i = 0; i < n; ++i) {
    x[i] += h * vx[i];
    y[i] += h * vy[i];
    z[i] += h * vz[i];
    const Real dx = x[i] - x0[i], dy = y[i] - y0[i], dz = z[i] - z0[i];
    const Real d2 = dx * dx + dy * dy + dz * dz;
    m = d2 > m ? d2 : m;
    sum += d2;
  }
  if (!std::isfinite(sum)) return std::numeric_limits<double>::infinity();
  return double(m);
}

template <class Real>
void zero_forces(Particles<Real>& p) {
  std::fill(p.fx.begin(), p.fx.end(), Real(0));
  std::fill(p.fy.begin(), p.fy.end(), Real(0));
  std::fill(p.fz.begin(), p.fz.end(), Real(0));
}

template <class Real>
double kinetic_energy(const Particles<Real>& p) {
  double e = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i)
    e += 0.5 / double(p.inv_mass[i]) *
         double(p.vx[i] * p.vx[i] + p.vy[i] * p.vy[i] + p.vz[i] * p.vz[i]);
  return e;
}

}  // namespace basalt::solver
