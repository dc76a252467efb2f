#pragma once
// Damping, as body forces on each particle of the given tags (ESyS-Particle "LinDamping" and
// "RotDamping", and Cundall's local damping):
//   linear_damping:      F = -nu m (v - v_ref)                   (ESyS LinDampingPrms viscosity nu)
//   rotational_damping:  T = -nu I w                             (ESyS RotDampingPrms viscosity nu)
//   With `iterations = N` both follow ESyS-Particle 2.3.5 exactly (Model/Damping.hpp, RotDamping.hpp;
//   docs/reference-runs.md): the damped velocity u solves u = v - v_ref + dt/m (F - nu m u) by fixed-
//   point iteration from u = 0 while |du|^4 > 1e-12 and fewer than N iterations were made (F the
//   force from every other model); N iterations made (converged or not) means no damping that step.
//   local_damping:       F_k -= alpha |F_k| sign(v_k), each component k of the force from every other
//                        model (non-viscous; alpha in [0, 1); Cundall 1987, as in PFC and Yade's
//                        NewtonIntegrator damping), and the same on torques with w.
// The energy they take out goes to the ledger term damping_dissipated (the power F . v over each step).
#include <array>
#include <cmath>
#include <cstdint>
#include <string_view>
#include <type_traits>

#include "basalt/solver/models/lanes.hpp"
#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

struct LinearDamping {
  static constexpr std::string_view name = "linear_damping";
  static constexpr ModelKind kind = ModelKind::body;
  static constexpr std::string_view summary = "F = -nu m (v - v_ref) (ESyS LinDamping)";
  static constexpr std::string_view energy_term = {};
  static constexpr std::string_view dissipation_term = "damping_dissipated";
  static constexpr std::array keys{
      KeyDoc{"viscosity", "nu, 1/time, >= 0 (required)"},
      KeyDoc{"reference_velocity", "[vx, vy, vz] (default 0)"},
      KeyDoc{"iterations",
             "ESyS's implicit form with at most this many iterations (its maxIterations; default: none, "
             "F = -nu m (v - v_ref))"},
      KeyDoc{"tags", "particle tags it acts on (default: all)"}};
  static constexpr Fields reads = kVelocity | kInverseMass | kTag;
  static constexpr Fields writes = kForce;

  struct Params {
    double nu = 0;
    std::array<double, 3> v_ref{0, 0, 0};
    std::int64_t iterations = 0;  ///< 0: explicit
  };
  template <class Real>
  struct Coeffs {
    Real nu, vx, vy, vz;
    int iterations;
  };
  struct History {};

  static Params parse(TableReader& t) {
    Params p;
    p.nu = t.non_negative("viscosity");
    if (t.has("reference_velocity")) p.v_ref = t.vec3("reference_velocity");
    p.iterations = iterations(t);
    return p;
  }
  static std::int64_t iterations(TableReader& t) {
    const auto n = t.integer_or("iterations", 0);
    if (n < 0 || n > 100000) t.fail("iterations", "must be in 1 .. 100000 (or absent)");
    return n;
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {Real(p.nu), Real(p.v_ref[0]), Real(p.v_ref[1]), Real(p.v_ref[2]), static_cast<int>(p.iterations)};
  }
  static double max_stiffness(const Params&, double) { return 0; }

  /// ESyS's damped velocity: u = v + s dt (F - nu M u) iterated from 0 (s = 1 / M), or 0 when the
  /// iteration limit is reached.
  template <class Real>
  static std::array<Real, 3> esys_velocity(Real nu, Real M, Real s, Real dt, int n, std::array<Real, 3> v,
                                           std::array<Real, 3> F) {
    std::array<Real, 3> u{0, 0, 0};
    double error = 1;
    int count = 0;
    while (error * error > 1e-12 && count < n) {
      ++count;
      const auto old = u;
      for (int d = 0; d < 3; ++d) u[d] = v[d] + s * dt * (F[d] - u[d] * nu * M);
      error = double((u[0] - old[0]) * (u[0] - old[0]) + (u[1] - old[1]) * (u[1] - old[1]) +
                     (u[2] - old[2]) * (u[2] - old[2]));
    }
    if (count >= n) u = {0, 0, 0};
    return u;
  }

  /// The smallest float e with double(e)^2 > 1e-12 (the square of a float is exact in double):
  /// esys_velocity goes on iterating from a float error e exactly when e >= kFloatGo (test
  /// Damping.FloatStopIsEsysStop).
  static constexpr float kFloatGo = 0x1.0c6f7cp-20f;

  /// The first two of esys_velocity's iterations (n > 0; n = 0 leaves u = v), branch-free (a vector loop
  /// runs it for many particles side by side): u after them, and whether the particle iterates on (then
  /// only esys_velocity gives its u). The same arithmetic in the same order: where it stops, u is
  /// esys_velocity's bit for bit. (ESyS's test stops nearly every particle after one or two: the second
  /// update is nu dt times the first.)
  template <class Real>
  [[gnu::always_inline]] static inline bool esys_two(Real nu, Real M, Real s, Real dt, int n, Real vx,
                                                     Real vy, Real vz, Real Fx, Real Fy, Real Fz, Real& ux,
                                                     Real& uy, Real& uz) {
    const bool iterated = n > 0;  // (else the explicit form: u = v)
    const Real limit = Real(n);
    Real count = 0;
    // Whether the lane still iterates, as 0 or 1 (bools here let GCC branch on a comparison, which may
    // trap, and then give up vectorising the loop). The first test, error = 1 > 1e-6, always passes.
    Real on = iterated ? 1 : 0;
    ux = iterated ? Real(0) : vx;
    uy = iterated ? Real(0) : vy;
    uz = iterated ? Real(0) : vz;
    for (int it = 0; it < 2; ++it) {
      const Real x = vx + s * dt * (Fx - ux * nu * M);
      const Real y = vy + s * dt * (Fy - uy * nu * M);
      const Real z = vz + s * dt * (Fz - uz * nu * M);
      const Real e = (x - ux) * (x - ux) + (y - uy) * (y - uy) + (z - uz) * (z - uz);
      // (quiet comparisons, the isgreater family: an ordered one may trap on a NaN, and GCC then will not
      // turn the loop's branches into selects, nor vectorise it)
      Real go;  // (0 or 1 as Real, as `on`: GCC 12 does not vectorise a select between two masks)
      if constexpr (std::is_same_v<Real, float>)
        go = __builtin_isgreaterequal(e, kFloatGo) ? 1 : 0;  // esys_velocity's test on a float error
      else
        go = __builtin_isgreater(double(e) * double(e), 1e-12) ? 1 : 0;
      const bool step = on != 0;
      ux = step ? x : ux;
      uy = step ? y : uy;
      uz = step ? z : uz;
      count += on;
      on = on * go * (__builtin_isless(count, limit) ? Real(1) : Real(0));
    }
    const bool spent = iterated & __builtin_isgreaterequal(count, limit);
    ux = spent ? 0 : ux;
    uy = spent ? 0 : uy;
    uz = spent ? 0 : uz;
    return on != 0;
  }

  /// Damping on every particle: one loop in vector registers, then esys_velocity for the few particles
  /// still iterating after two updates (their force is left out of the loop), so that each particle gets
  /// exactly apply()'s force. v - v_ref is the velocity damped and F the force it is added to (linear: v and
  /// F; rotational: w and the torque); inertia(i) gives M and s = 1 / M as the model's apply() takes them
  /// (linear: 1 / m_inv and m_inv as stored; rotational: I and 1 / I).
  template <class Real, class Inertia>
  BASALT_WIDE_LANES static void damp_all(Real nu, int n, Real dt, std::size_t np, Inertia inertia, Real rx,
                                         Real ry, Real rz, const Real* __restrict vx,
                                         const Real* __restrict vy, const Real* __restrict vz,
                                         Real* __restrict fx, Real* __restrict fy, Real* __restrict fz,
                                         double* __restrict out, std::uint8_t* __restrict more) {
    // (the arrays are distinct: without ivdep GCC wants more run-time alias tests than it makes)
    unsigned any = 0;  // some particle iterates on (rare: the scan below is a fifth of the damping's time)
#pragma GCC ivdep
    for (std::size_t i = 0; i < np; ++i) {
      const auto [M, s] = inertia(i);
      Real ux = vx[i] - rx, uy = vy[i] - ry, uz = vz[i] - rz;
      const bool on = esys_two(nu, M, s, dt, n, ux, uy, uz, fx[i], fy[i], fz[i], ux, uy, uz);
      any |= on;
      const Real k = -nu * M;
      const Real gx = k * ux, gy = k * uy, gz = k * uz;
      out[i] = -double(gx * vx[i] + gy * vy[i] + gz * vz[i]) * double(dt);
      fx[i] = on ? fx[i] : fx[i] + gx;
      fy[i] = on ? fy[i] : fy[i] + gy;
      fz[i] = on ? fz[i] : fz[i] + gz;
      more[i] = on;
    }
    if (any == 0) return;
    for (std::size_t i = 0; i < np; ++i) {
      if (more[i] == 0) [[likely]]
        continue;
      const auto [M, s] = inertia(i);
      const auto u =
          esys_velocity(nu, M, s, dt, n, {vx[i] - rx, vy[i] - ry, vz[i] - rz}, {fx[i], fy[i], fz[i]});
      const Real k = -nu * M;
      const Real gx = k * u[0], gy = k * u[1], gz = k * u[2];
      out[i] = -double(gx * vx[i] + gy * vy[i] + gz * vz[i]) * double(dt);
      fx[i] += gx, fy[i] += gy, fz[i] += gz;
    }
  }

  /// F = -nu m u (u = v - v_ref, or ESyS's damped velocity) on every particle (damp_all; 512-bit vectors
  /// here too, or damp_all is inlined into a caller that prefers 256-bit ones: 1.2x the time).
  template <class Real>
  BASALT_WIDE_LANES static void apply_all(const Coeffs<Real>& c, const BodyArrays<Real>& a) {
    const Real* im = a.im;
    const auto inertia = [im](std::size_t i) { return std::array<Real, 2>{Real(1) / im[i], im[i]}; };
    damp_all(c.nu, c.iterations, a.dt, a.n, inertia, c.vx, c.vy, c.vz, a.vx, a.vy, a.vz, a.fx, a.fy, a.fz,
             a.dissipated, a.flag);
  }

  template <class Real>
  static void apply(const Coeffs<Real>& c, const BodyState<Real>& b, BodyForce<Real>& f) {
    std::array<Real, 3> u{b.vx - c.vx, b.vy - c.vy, b.vz - c.vz};
    if (c.iterations > 0) u = esys_velocity(c.nu, b.m, b.im, b.dt, c.iterations, u, {b.fx, b.fy, b.fz});
    const Real s = -c.nu * b.m;
    f.fx = s * u[0];
    f.fy = s * u[1];
    f.fz = s * u[2];
    f.dissipated = -double(f.fx * b.vx + f.fy * b.vy + f.fz * b.vz) * double(b.dt);
  }
  template <class Real>
  static Real energy(const Coeffs<Real>&, const BodyState<Real>&) {
    return 0;
  }
};

struct RotationalDamping {
  static constexpr std::string_view name = "rotational_damping";
  static constexpr ModelKind kind = ModelKind::body;
  static constexpr std::string_view summary = "T = -nu I w (ESyS RotDamping)";
  static constexpr std::string_view energy_term = {};
  static constexpr std::string_view dissipation_term = "damping_dissipated";
  static constexpr std::array keys{
      KeyDoc{"viscosity", "nu, 1/time, >= 0 (required)"},
      KeyDoc{"iterations",
             "ESyS's implicit form with at most this many iterations (default: none, T = -nu I w)"},
      KeyDoc{"tags", "particle tags it acts on (default: all)"}};
  static constexpr Fields reads = kAngularVelocity | kInverseMass | kRadius | kTag;
  static constexpr Fields writes = kTorque;

  struct Params {
    double nu = 0;
    std::int64_t iterations = 0;
  };
  template <class Real>
  struct Coeffs {
    Real nu;
    int iterations;
  };
  struct History {};

  static Params parse(TableReader& t) {
    Params p{t.non_negative("viscosity")};
    p.iterations = LinearDamping::iterations(t);
    return p;
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {Real(p.nu), static_cast<int>(p.iterations)};
  }
  static double max_stiffness(const Params&, double) { return 0; }

  /// I as BodyDriver::loop takes it: 1 / Particles::inverse_inertia.
  template <class Real>
  static Real inertia(Real im, Real r) {
    return Real(1) / (Real(2.5) * im / (r * r));
  }

  /// T = -nu I w (w ESyS's damped spin) on every particle (LinearDamping::damp_all).
  template <class Real>
  BASALT_WIDE_LANES static void apply_all(const Coeffs<Real>& c, const BodyArrays<Real>& a) {
    const Real *im = a.im, *rad = a.radius;
    const auto turning = [im, rad](std::size_t i) {
      const Real I = inertia(im[i], rad[i]);
      return std::array<Real, 2>{I, Real(1) / I};
    };
    LinearDamping::damp_all(c.nu, c.iterations, a.dt, a.n, turning, Real(0), Real(0), Real(0), a.wx, a.wy,
                            a.wz, a.tx, a.ty, a.tz, a.dissipated, a.flag);
  }

  template <class Real>
  static void apply(const Coeffs<Real>& c, const BodyState<Real>& b, BodyForce<Real>& f) {
    std::array<Real, 3> u{b.wx, b.wy, b.wz};
    if (c.iterations > 0)
      u = LinearDamping::esys_velocity(c.nu, b.inertia, Real(1) / b.inertia, b.dt, c.iterations, u,
                                       {b.tx, b.ty, b.tz});
    const Real s = -c.nu * b.inertia;
    f.tx = s * u[0];
    f.ty = s * u[1];
    f.tz = s * u[2];
    f.dissipated = -double(f.tx * b.wx + f.ty * b.wy + f.tz * b.wz) * double(b.dt);
  }
  template <class Real>
  static Real energy(const Coeffs<Real>&, const BodyState<Real>&) {
    return 0;
  }
};

struct LocalDamping {
  static constexpr std::string_view name = "local_damping";
  static constexpr ModelKind kind = ModelKind::body;
  static constexpr std::string_view summary =
      "F_k -= alpha |F_k| sign(v_k) on each force and torque component (Cundall's local damping)";
  static constexpr std::string_view energy_term = {};
  static constexpr std::string_view dissipation_term = "damping_dissipated";
  static constexpr std::array keys{KeyDoc{"alpha", "damping coefficient, 0 <= alpha < 1 (required)"},
                                   KeyDoc{"tags", "particle tags it acts on (default: all)"}};
  static constexpr Fields reads = kVelocity | kForce | kTag;
  static constexpr Fields writes = kForce | kTorque;

  struct Params {
    double alpha = 0;
  };
  template <class Real>
  struct Coeffs {
    Real alpha;
  };
  struct History {};

  static Params parse(TableReader& t) {
    Params p{t.non_negative("alpha")};
    if (p.alpha >= 1) t.fail("alpha", "must be < 1 (alpha = 1 would cancel every force)");
    return p;
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {Real(p.alpha)};
  }
  static double max_stiffness(const Params&, double) { return 0; }

  template <class Real>
  static void apply(const Coeffs<Real>& c, const BodyState<Real>& b, BodyForce<Real>& f) {
    const auto damp = [&](Real force, Real v) {
      return v == Real(0) ? Real(0) : -c.alpha * std::abs(force) * (v > 0 ? Real(1) : Real(-1));
    };
    f.fx = damp(b.fx, b.vx);
    f.fy = damp(b.fy, b.vy);
    f.fz = damp(b.fz, b.vz);
    f.tx = damp(b.tx, b.wx);
    f.ty = damp(b.ty, b.wy);
    f.tz = damp(b.tz, b.wz);
    f.dissipated =
        -double(f.fx * b.vx + f.fy * b.vy + f.fz * b.vz + f.tx * b.wx + f.ty * b.wy + f.tz * b.wz) *
        double(b.dt);
  }
  template <class Real>
  static Real energy(const Coeffs<Real>&, const BodyState<Real>&) {
    return 0;
  }
};

}  // namespace basalt::solver
