#pragma once
// Time integration of owned particles, split into a kick (v += F/m h) and a drift (x += v h).
//   velocity Verlet:  kick(dt/2), drift(dt), forces, kick(dt/2)
//   symplectic Euler: kick(dt),   drift(dt), forces            (ESyS-Particle's scheme)
// The first kick and the drift run fused in kick_zero_drift(), which returns the largest squared
// displacement since the last rebuild (inf if any position went non-finite): it decides the next
// neighbour-list rebuild.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "basalt/solver/core/particles.hpp"

namespace basalt::solver {

namespace detail {
/// The half-kick v += h f / m, and with Energy also the kinetic energy of the kicked velocities
/// (sum of m v^2 / 2, particle i in lane i mod 8). Returns 0 without Energy.
template <bool Energy, class Real>
double kick_pass(Particles<Real>& p, Real h);
}  // namespace detail

template <class Real>
void kick(Particles<Real>& p, Real h) {
  detail::kick_pass<false>(p, h);
}

namespace detail {
/// x += u dt by Kahan's compensated sum: c carries what rounding dropped from x (x - c is the
/// position), fed back into the next increment.
template <class Real>
inline void drift_compensated(Real& x, Real& c, Real u, Real dt) {
  const Real y = dt * u - c;
  const Real t = x + y;
  c = (t - x) - y;
  x = t;
}

/// With Pending, the half-kick h0 left over from the step before comes first: v + h0 f / m rounded, then
/// + h f / m, the operations of kick(p, h0) followed by the pass without it.
template <bool Compensated, bool Pending, class Real>
double kick_zero_drift(Particles<Real>& p, Real h0, Real h, Real dt) {
  const std::size_t n = p.n_owned;
  Real* __restrict x = p.x.data();
  Real* __restrict y = p.y.data();
  Real* __restrict z = p.z.data();
  Real* __restrict vx = p.vx.data();
  Real* __restrict vy = p.vy.data();
  Real* __restrict vz = p.vz.data();
  Real* __restrict fx = p.fx.data();
  Real* __restrict fy = p.fy.data();
  Real* __restrict fz = p.fz.data();
  const Real* __restrict im = p.inv_mass.data();
  const float* __restrict x0 = p.x0.data();
  const float* __restrict y0 = p.y0.data();
  const float* __restrict z0 = p.z0.data();
  const Real ox = Real(p.skin_origin[0]), oy = Real(p.skin_origin[1]), oz = Real(p.skin_origin[2]);
  Real* __restrict cx = p.cx.data();  // empty without compensation (never read then)
  Real* __restrict cy = p.cy.data();
  Real* __restrict cz = p.cz.data();
  // The largest d2 is taken on its bits as a signed integer, which order as the values do for d2 >= 0:
  // GCC keeps a floating-point max (NaN rules) or sum (order) out of vector registers, not an integer one.
  // Non-finite displacements are counted apart.
  using Bits = std::conditional_t<sizeof(Real) == 8, std::int64_t, std::int32_t>;
  Bits m = 0;
  std::size_t bad = 0;
  // ivdep: GCC does not take __restrict on locals as proof that the arrays are distinct (they are).
#pragma GCC ivdep
  for (std::size_t i = 0; i < n; ++i) {
    Real wx = vx[i], wy = vy[i], wz = vz[i];
    if constexpr (Pending) {
      const Real s0 = h0 * im[i];
      wx += s0 * fx[i];
      wy += s0 * fy[i];
      wz += s0 * fz[i];
    }
    const Real s = h * im[i];
    const Real ux = wx + s * fx[i], uy = wy + s * fy[i], uz = wz + s * fz[i];
    vx[i] = ux;
    vy[i] = uy;
    vz[i] = uz;
    fx[i] = 0;
    fy[i] = 0;
    fz[i] = 0;
    if constexpr (Compensated) {
      drift_compensated(x[i], cx[i], ux, dt);
      drift_compensated(y[i], cy[i], uy, dt);
      drift_compensated(z[i], cz[i], uz, dt);
    } else {
      x[i] += dt * ux;
      y[i] += dt * uy;
      z[i] += dt * uz;
    }
    const Real dx = x[i] - ox - x0[i], dy = y[i] - oy - y0[i], dz = z[i] - oz - z0[i];
    const Real d2 = dx * dx + dy * dy + dz * dz;
    const Bits bits = std::bit_cast<Bits>(d2);
    m = bits > m ? bits : m;
    bad += !(d2 <= std::numeric_limits<Real>::max());
  }
  if (bad > 0) return std::numeric_limits<double>::infinity();
  return double(std::bit_cast<Real>(m));
}
}  // namespace detail

/// kick(h), zero the forces (the next force computation accumulates from zero), drift(dt), in one
/// pass over memory; the drift compensated (Kahan) when p.with_compensation. Returns the largest squared
/// displacement since the last rebuild, or infinity when a position went non-finite.
template <class Real>
double kick_zero_drift(Particles<Real>& p, Real h, Real dt) {
  return p.with_compensation ? detail::kick_zero_drift<true, false>(p, Real(0), h, dt)
                             : detail::kick_zero_drift<false, false>(p, Real(0), h, dt);
}

/// kick(p, h0), then kick_zero_drift(p, h, dt), in one pass over memory: velocity Verlet's second half-kick
/// of the step before (Simulation::run() defers it when nothing reads the velocities in between) and this
/// step's first. The same operations in the same order as the two calls, so the same bits, with one pass
/// fewer over v, f and 1/m.
template <class Real>
double kick_kick_zero_drift(Particles<Real>& p, Real h0, Real h, Real dt) {
  return p.with_compensation ? detail::kick_zero_drift<true, true>(p, h0, h, dt)
                             : detail::kick_zero_drift<false, true>(p, h0, h, dt);
}

/// The half angle a^2 = (|w| dt / 2)^2 below which half_turn() takes the Taylor series.
template <class Real>
inline constexpr Real kTaylorTurn = Real(1e-2);

/// cos(a) and sin(a) / w by their Taylor series through a^8, from a2 = a^2 and h = dt / 2: for
/// a2 < kTaylorTurn the first omitted term is below 3e-17 relative (under an ulp).
template <class Real>
inline void half_turn_series(Real a2, Real h, Real& c, Real& s) {
  c = Real(1) +
      a2 * (Real(-1.0 / 2) + a2 * (Real(1.0 / 24) + a2 * (Real(-1.0 / 720) + a2 * Real(1.0 / 40320))));
  s = h * (Real(1) + a2 * (Real(-1.0 / 6) +
                           a2 * (Real(1.0 / 120) + a2 * (Real(-1.0 / 5040) + a2 * Real(1.0 / 362880)))));
}

/// cos(a) and sin(a) / w for the half angle a = |w| dt / 2 of a step's turn, from w2 = |w|^2: for
/// a^2 < 1e-2 (every step of a stable run turns by far less) by half_turn_series (the same to rounding as
/// std::sin and std::cos, with no square root, division or call); above, by std::sin and std::cos.
template <class Real>
inline void half_turn(Real w2, Real dt, Real& c, Real& s) {
  const Real h = Real(0.5) * dt, a2 = w2 * h * h;
  if (a2 < kTaylorTurn<Real>) return half_turn_series(a2, h, c, s);
  const Real w = std::sqrt(w2), a = h * w;
  c = std::cos(a);
  s = std::sin(a) / w;
}

namespace detail {
/// q <- dq q for dq = (c, s w), then q back to unit length, as ESyS-Particle after every step
/// (CRotParticle::rescale: q times 1/|q|). The turn keeps |q| to rounding per step, but the roundings add
/// up (|q|^2 - 1 reached 6e-14 in 3,000 steps), and rot_bond's ESyS angles read a norm defect e as a bend
/// of sqrt(2 e): 1e-7 rad, a kick on every bond that pumped energy into a free specimen 5x faster than
/// ESyS (docs/validation-rock.md).
template <class Real>
inline void turn(Real c, Real sn, Real wx, Real wy, Real wz, Real& qw, Real& qx, Real& qy, Real& qz) {
  const Real ax = sn * wx, ay = sn * wy, az = sn * wz;
  const Real nw = c * qw - ax * qx - ay * qy - az * qz;
  const Real nx = c * qx + ax * qw + ay * qz - az * qy;
  const Real ny = c * qy + ay * qw + az * qx - ax * qz;
  const Real nz = c * qz + az * qw + ax * qy - ay * qx;
  const Real inv = Real(1) / std::sqrt(nw * nw + nx * nx + ny * ny + nz * nz);
  qw = nw * inv;
  qx = nx * inv;
  qy = ny * inv;
  qz = nz * inv;
}
}  // namespace detail

/// Rotation (with_rotation), the twin of kick_zero_drift: w += h T / I (I = 2/5 m r^2: a sphere needs
/// no gyroscopic term), torques zeroed, then (with_orientation) the orientation turned by the angle
/// |w| dt about w (an exact rotation for the step's constant w) and brought back to unit length. A particle
/// at rest (w = 0) keeps its orientation bit for bit. The pass has no branch, so that it runs in vector
/// registers: a turn too large for the series (a2 >= kTaylorTurn, never in a stable run) leaves its
/// orientation alone there and is made by sin and cos in a second pass, which only runs when there is one.
namespace detail {
/// Turn: the particles keep orientations (with_orientation); without, the pass is the kick alone, the
/// same operations on w in the same order, so the same bits.
template <bool Pending, bool Turn, class Real>
void rotate_kick_zero_drift(Particles<Real>& p, Real h0, Real h, Real dt) {
  const std::size_t n = p.n_owned;
  const Real* __restrict im = p.inv_mass.data();
  const Real* __restrict rad = p.radius.data();
  Real* __restrict wxs = p.wx.data();
  Real* __restrict wys = p.wy.data();
  Real* __restrict wzs = p.wz.data();
  Real* __restrict tx = p.tx.data();
  Real* __restrict ty = p.ty.data();
  Real* __restrict tz = p.tz.data();
  Real* __restrict qws = p.qw.data();
  Real* __restrict qxs = p.qx.data();
  Real* __restrict qys = p.qy.data();
  Real* __restrict qzs = p.qz.data();
  const Real hh = Real(0.5) * dt;
  std::size_t large = 0;  // turns left to the second pass (NaN included)
  // ivdep: GCC does not take __restrict on locals as proof that the arrays are distinct (they are).
#pragma GCC ivdep
  for (std::size_t i = 0; i < n; ++i) {
    Real ox = wxs[i], oy = wys[i], oz = wzs[i];
    if constexpr (Pending) {
      const Real s0 = h0 * (Real(2.5) * im[i] / (rad[i] * rad[i]));  // as rotate_kick()
      ox += s0 * tx[i];
      oy += s0 * ty[i];
      oz += s0 * tz[i];
    }
    const Real s = h * (Real(2.5) * im[i] / (rad[i] * rad[i]));  // inverse_inertia(i)
    const Real wx = ox + s * tx[i], wy = oy + s * ty[i], wz = oz + s * tz[i];
    wxs[i] = wx;
    wys[i] = wy;
    wzs[i] = wz;
    tx[i] = 0;
    ty[i] = 0;
    tz[i] = 0;
    if constexpr (Turn) {
      const Real w2 = wx * wx + wy * wy + wz * wz, a2 = w2 * hh * hh;  // as half_turn(): the same bits
      large += !(a2 < kTaylorTurn<Real>);
      Real c, sn, qw = qws[i], qx = qxs[i], qy = qys[i], qz = qzs[i];
      half_turn_series(a2, hh, c, sn);
      detail::turn(c, sn, wx, wy, wz, qw, qx, qy, qz);
      // At rest (w = 0) the orientation keeps its bits; a turn too large for the series waits for the pass
      // below.
      const bool keep = w2 == Real(0) || !(a2 < kTaylorTurn<Real>);
      qws[i] = keep ? qws[i] : qw;
      qxs[i] = keep ? qxs[i] : qx;
      qys[i] = keep ? qys[i] : qy;
      qzs[i] = keep ? qzs[i] : qz;
    }
  }
  if (!Turn || large == 0) return;
  for (std::size_t i = 0; i < n; ++i) {
    const Real wx = wxs[i], wy = wys[i], wz = wzs[i];
    const Real w2 = wx * wx + wy * wy + wz * wz;
    if (w2 * hh * hh < kTaylorTurn<Real>) continue;
    Real c, sn;
    half_turn(w2, dt, c, sn);
    detail::turn(c, sn, wx, wy, wz, qws[i], qxs[i], qys[i], qzs[i]);
  }
}
}  // namespace detail

template <class Real>
void rotate_kick_zero_drift(Particles<Real>& p, Real h, Real dt) {
  if (p.with_orientation)
    detail::rotate_kick_zero_drift<false, true>(p, Real(0), h, dt);
  else
    detail::rotate_kick_zero_drift<false, false>(p, Real(0), h, dt);
}

/// rotate_kick(p, h0), then rotate_kick_zero_drift(p, h, dt), in one pass over memory (as
/// kick_kick_zero_drift): the same bits.
template <class Real>
void rotate_kick_kick_zero_drift(Particles<Real>& p, Real h0, Real h, Real dt) {
  if (p.with_orientation)
    detail::rotate_kick_zero_drift<true, true>(p, h0, h, dt);
  else
    detail::rotate_kick_zero_drift<true, false>(p, h0, h, dt);
}

/// The rotational half-kick w += h T / I.
template <class Real>
void rotate_kick(Particles<Real>& p, Real h) {
  const std::size_t n = p.n_owned;
  const Real* __restrict im = p.inv_mass.data();
  const Real* __restrict rad = p.radius.data();
  Real* __restrict wx = p.wx.data();
  Real* __restrict wy = p.wy.data();
  Real* __restrict wz = p.wz.data();
  const Real* __restrict tx = p.tx.data();
  const Real* __restrict ty = p.ty.data();
  const Real* __restrict tz = p.tz.data();
  // ivdep: GCC does not take __restrict on locals as proof that the arrays are distinct (they are).
#pragma GCC ivdep
  for (std::size_t i = 0; i < n; ++i) {
    const Real s = h * (Real(2.5) * im[i] / (rad[i] * rad[i]));  // inverse_inertia(i)
    wx[i] += s * tx[i];
    wy[i] += s * ty[i];
    wz[i] += s * tz[i];
  }
}

/// Rotational kinetic energy of the owned particles, sum of I w^2 / 2 (fixed order: deterministic).
template <class Real>
double rotational_energy(const Particles<Real>& p) {
  if (!p.with_rotation) return 0;
  double e = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const double w2 = double(p.wx[i]) * double(p.wx[i]) + double(p.wy[i]) * double(p.wy[i]) +
                      double(p.wz[i]) * double(p.wz[i]);
    e += w2 / double(p.inverse_inertia(i));
  }
  return 0.5 * e;
}

template <class Real>
void zero_forces(Particles<Real>& p) {
  std::fill(p.fx.begin(), p.fx.end(), Real(0));
  std::fill(p.fy.begin(), p.fy.end(), Real(0));
  std::fill(p.fz.begin(), p.fz.end(), Real(0));
  std::fill(p.tx.begin(), p.tx.end(), Real(0));
  std::fill(p.ty.begin(), p.ty.end(), Real(0));
  std::fill(p.tz.begin(), p.tz.end(), Real(0));
}

namespace detail {
/// Particle i adds v^2 * m to lane i mod 8, with m = 1 / (1/m) rounded once: the one formula and
/// summation order shared by kinetic_energy() and kick_energy(), so both give the same bits.
constexpr std::size_t kEnergyLanes = 8;
inline double lane_sum(const double (&lane)[kEnergyLanes]) {
  double e = 0;
  for (double l : lane) e += l;
  return 0.5 * e;
}
}  // namespace detail

/// Total kinetic energy of the owned particles, sum of m v^2 / 2. Eight independent partial sums
/// (particle i goes to lane i mod 8) let the compiler vectorise; the order is fixed, so the result
/// is deterministic.
template <class Real>
double kinetic_energy(const Particles<Real>& p) {
  double lane[detail::kEnergyLanes] = {};
  const Real* vx = p.vx.data();
  const Real* vy = p.vy.data();
  const Real* vz = p.vz.data();
  const Real* im = p.inv_mass.data();
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const double v2 =
        double(vx[i]) * double(vx[i]) + double(vy[i]) * double(vy[i]) + double(vz[i]) * double(vz[i]);
    lane[i % detail::kEnergyLanes] += v2 * (1.0 / double(im[i]));
  }
  return detail::lane_sum(lane);
}

/// kick(h) fused with the kinetic energy of the kicked velocities, sum of m v^2 / 2: one pass over
/// the velocities. The mass is 1 / inv_mass, divided in the pass: vectorised, the division hides under
/// the pass's memory traffic, where streaming cached masses cost an extra array (measured: 0.018 ms
/// per step on the 30 mm cube with a mass cache, none visible this way; 0.3-0.5 against 0.1-0.2 ms on
/// the 590 k-particle cube).
template <class Real>
double kick_energy(Particles<Real>& p, Real h) {
  return detail::kick_pass<true>(p, h);
}

namespace detail {
/// The loop of kick_pass over plain restrict-qualified arguments: GCC 12 honours restrict on
/// parameters, not on local pointers taken from the particle arrays, and vectorises only this way.
template <bool Energy, class Real>
double kick_loop(Real* __restrict vx, Real* __restrict vy, Real* __restrict vz, const Real* __restrict fx,
                 const Real* __restrict fy, const Real* __restrict fz, const Real* __restrict im, Real h,
                 std::size_t n) {
  double lane[kEnergyLanes] = {};
  std::size_t i = 0;
  if constexpr (Energy) {
    // Blocks of eight, lane l taking particle i + l (a flat loop adding to lane[i % 8] is not
    // vectorised). Particle i still adds to lane i mod 8 in increasing i: kinetic_energy()'s bits.
    for (; i + kEnergyLanes <= n; i += kEnergyLanes)
      for (std::size_t l = 0; l < kEnergyLanes; ++l) {
        const std::size_t k = i + l;
        const Real s = h * im[k];
        const Real ux = vx[k] + s * fx[k], uy = vy[k] + s * fy[k], uz = vz[k] + s * fz[k];
        vx[k] = ux;
        vy[k] = uy;
        vz[k] = uz;
        lane[l] += (double(ux) * double(ux) + double(uy) * double(uy) + double(uz) * double(uz)) *
                   (1.0 / double(im[k]));
      }
  }
  for (; i < n; ++i) {
    const Real s = h * im[i];
    vx[i] += s * fx[i];
    vy[i] += s * fy[i];
    vz[i] += s * fz[i];
    if constexpr (Energy) {
      const double v2 =
          double(vx[i]) * double(vx[i]) + double(vy[i]) * double(vy[i]) + double(vz[i]) * double(vz[i]);
      lane[i % kEnergyLanes] += v2 * (1.0 / double(im[i]));
    }
  }
  return Energy ? lane_sum(lane) : 0.0;
}
}  // namespace detail

template <bool Energy, class Real>
double detail::kick_pass(Particles<Real>& p, Real h) {
  return kick_loop<Energy>(p.vx.data(), p.vy.data(), p.vz.data(), p.fx.data(), p.fy.data(), p.fz.data(),
                           p.inv_mass.data(), h, p.n_owned);
}

}  // namespace basalt::solver
