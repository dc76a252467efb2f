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
      const double error = double((x - ux) * (x - ux) + (y - uy) * (y - uy) + (z - uz) * (z - uz));
      const bool step = on != 0;
      ux = step ? x : ux;
      uy = step ? y : uy;
      uz = step ? z : uz;
      count += step ? 1 : 0;
      on = step && error * error > 1e-12 && count < limit ? 1 : 0;
    }
    const bool spent = iterated && count >= limit;
    ux = spent ? 0 : ux;
    uy = spent ? 0 : uy;
    uz = spent ? 0 : uz;
    return on != 0;
  }

  /// F = -nu m u (u = v - v_ref, or ESyS's damped velocity) on every particle: one loop in vector
  /// registers, then esys_velocity for the few particles still iterating after two updates (their force is
  /// left out of the loop, so that both give exactly apply()'s force).
  template <class Real>
  BASALT_WIDE_LANES static void apply_all(const Coeffs<Real>& c, const BodyArrays<Real>& a) {
    const Real nu = c.nu, dt = a.dt, rx = c.vx, ry = c.vy, rz = c.vz;
    const int n = c.iterations;
    const Real* __restrict im = a.im, * __restrict vx = a.vx, * __restrict vy = a.vy, * __restrict vz = a.vz;
    Real* __restrict fx = a.fx, * __restrict fy = a.fy, * __restrict fz = a.fz;
    double* __restrict out = a.dissipated;
    std::uint8_t* __restrict more = a.flag;
    const std::size_t np = a.n;  // (a local: the byte stores through `more` may alias a.n)
    // (the arrays are distinct: without ivdep GCC wants more run-time alias tests than it makes)
#pragma GCC ivdep
    for (std::size_t i = 0; i < np; ++i) {
      const Real m = Real(1) / im[i];
      Real ux = vx[i] - rx, uy = vy[i] - ry, uz = vz[i] - rz;
      const bool on = esys_two(nu, m, im[i], dt, n, ux, uy, uz, fx[i], fy[i], fz[i], ux, uy, uz);
      const Real k = -nu * m;
      const Real gx = k * ux, gy = k * uy, gz = k * uz;
      out[i] = -double(gx * vx[i] + gy * vy[i] + gz * vz[i]) * double(dt);
      fx[i] = on ? fx[i] : fx[i] + gx;
      fy[i] = on ? fy[i] : fy[i] + gy;
      fz[i] = on ? fz[i] : fz[i] + gz;
      more[i] = on;
    }
    for (std::size_t i = 0; i < np; ++i) {
      if (more[i] == 0) [[likely]]
        continue;
      BodyState<Real> b{};
      b.m = Real(1) / im[i], b.im = im[i], b.dt = dt;
      b.vx = vx[i], b.vy = vy[i], b.vz = vz[i], b.fx = fx[i], b.fy = fy[i], b.fz = fz[i];
      BodyForce<Real> f;
      apply(c, b, f);
      fx[i] += f.fx, fy[i] += f.fy, fz[i] += f.fz;
      out[i] = f.dissipated;
    }
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

  /// T = -nu I w (w ESyS's damped spin) on every particle, as LinearDamping::apply_all.
  template <class Real>
  BASALT_WIDE_LANES static void apply_all(const Coeffs<Real>& c, const BodyArrays<Real>& a) {
    const Real nu = c.nu, dt = a.dt;
    const int n = c.iterations;
    const Real* __restrict im = a.im, * __restrict rad = a.radius;
    const Real* __restrict wx = a.wx, * __restrict wy = a.wy, * __restrict wz = a.wz;
    Real* __restrict tx = a.tx, * __restrict ty = a.ty, * __restrict tz = a.tz;
    double* __restrict out = a.dissipated;
    std::uint8_t* __restrict more = a.flag;
    const std::size_t np = a.n;  // (a local: the byte stores through `more` may alias a.n)
    // (the arrays are distinct: without ivdep GCC wants more run-time alias tests than it makes)
#pragma GCC ivdep
    for (std::size_t i = 0; i < np; ++i) {
      const Real I = inertia(im[i], rad[i]);
      Real ux = wx[i], uy = wy[i], uz = wz[i];
      const bool on =
          LinearDamping::esys_two(nu, I, Real(1) / I, dt, n, ux, uy, uz, tx[i], ty[i], tz[i], ux, uy, uz);
      const Real k = -nu * I;
      const Real hx = k * ux, hy = k * uy, hz = k * uz;
      out[i] = -double(hx * wx[i] + hy * wy[i] + hz * wz[i]) * double(dt);
      tx[i] = on ? tx[i] : tx[i] + hx;
      ty[i] = on ? ty[i] : ty[i] + hy;
      tz[i] = on ? tz[i] : tz[i] + hz;
      more[i] = on;
    }
    for (std::size_t i = 0; i < np; ++i) {
      if (more[i] == 0) [[likely]]
        continue;
      BodyState<Real> b{};
      b.inertia = inertia(im[i], rad[i]), b.dt = dt;
      b.wx = wx[i], b.wy = wy[i], b.wz = wz[i], b.tx = tx[i], b.ty = ty[i], b.tz = tz[i];
      BodyForce<Real> f;
      apply(c, b, f);
      tx[i] += f.tx, ty[i] += f.ty, tz[i] += f.tz;
      out[i] = f.dissipated;
    }
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
