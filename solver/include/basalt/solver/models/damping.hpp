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

  /// esys_velocity for W particles side by side (M and s per lane; v in, the damped velocity u out):
  /// each lane iterates exactly as the scalar form and stops where it would, branch-free (a particle's
  /// iteration count depends on its speed: the scalar loop mispredicted it). Inputs and outputs are
  /// separate arrays: GCC 12 at -O2 lost a component of v in a form that overwrote it in place.
  template <class Real, int W>
  static void esys_velocity_lanes(Real nu, const Real* __restrict M, const Real* __restrict s, Real dt, int n,
                                  const Real* __restrict vx, const Real* __restrict vy,
                                  const Real* __restrict vz, const Real* __restrict Fx,
                                  const Real* __restrict Fy, const Real* __restrict Fz, Real* __restrict ux,
                                  Real* __restrict uy, Real* __restrict uz) {
    alignas(64) Real count[W], on[W];
    for (int l = 0; l < W; ++l) {
      ux[l] = 0;
      uy[l] = 0;
      uz[l] = 0;
      count[l] = 0;
      on[l] = n > 0 ? 1 : 0;  // (the first test, error = 1 > 1e-6, always passes)
    }
    const Real limit = Real(n);
    for (int it = 0; it < n; ++it) {
      Real any = 0;
      for (int l = 0; l < W; ++l) {
        const Real x = vx[l] + s[l] * dt * (Fx[l] - ux[l] * nu * M[l]);
        const Real y = vy[l] + s[l] * dt * (Fy[l] - uy[l] * nu * M[l]);
        const Real z = vz[l] + s[l] * dt * (Fz[l] - uz[l] * nu * M[l]);
        const double error =
            double((x - ux[l]) * (x - ux[l]) + (y - uy[l]) * (y - uy[l]) + (z - uz[l]) * (z - uz[l]));
        const bool step = on[l] != 0;
        ux[l] = step ? x : ux[l];
        uy[l] = step ? y : uy[l];
        uz[l] = step ? z : uz[l];
        count[l] += step ? 1 : 0;
        on[l] = step && error * error > 1e-12 && count[l] < limit ? 1 : 0;
        any += on[l];
      }
      if (any == 0) break;
    }
    for (int l = 0; l < W; ++l) {
      const bool spent = count[l] >= limit;
      ux[l] = spent ? 0 : ux[l];
      uy[l] = spent ? 0 : uy[l];
      uz[l] = spent ? 0 : uz[l];
    }
  }

  template <class Real, int W>
  static void apply_lanes(const Coeffs<Real>& c, BodyLanes<Real, W>& b) {
    alignas(64) Real vx[W], vy[W], vz[W], ux[W], uy[W], uz[W];
    for (int l = 0; l < W; ++l) vx[l] = b.vx[l] - c.vx, vy[l] = b.vy[l] - c.vy, vz[l] = b.vz[l] - c.vz;
    if (c.iterations > 0)
      esys_velocity_lanes<Real, W>(c.nu, b.m, b.im, b.dt, c.iterations, vx, vy, vz, b.fx, b.fy, b.fz, ux, uy,
                                   uz);
    else
      for (int l = 0; l < W; ++l) ux[l] = vx[l], uy[l] = vy[l], uz[l] = vz[l];
    for (int l = 0; l < W; ++l) {
      const Real s = -c.nu * b.m[l];
      b.gx[l] = s * ux[l];
      b.gy[l] = s * uy[l];
      b.gz[l] = s * uz[l];
      b.hx[l] = b.hy[l] = b.hz[l] = 0;
      b.dissipated[l] = -double(b.gx[l] * b.vx[l] + b.gy[l] * b.vy[l] + b.gz[l] * b.vz[l]) * double(b.dt);
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

  template <class Real, int W>
  static void apply_lanes(const Coeffs<Real>& c, BodyLanes<Real, W>& b) {
    alignas(64) Real ux[W], uy[W], uz[W], s[W];
    for (int l = 0; l < W; ++l) s[l] = Real(1) / b.inertia[l];
    if (c.iterations > 0)
      LinearDamping::esys_velocity_lanes<Real, W>(c.nu, b.inertia, s, b.dt, c.iterations, b.wx, b.wy, b.wz,
                                                  b.tx, b.ty, b.tz, ux, uy, uz);
    else
      for (int l = 0; l < W; ++l) ux[l] = b.wx[l], uy[l] = b.wy[l], uz[l] = b.wz[l];
    for (int l = 0; l < W; ++l) {
      const Real k = -c.nu * b.inertia[l];
      b.gx[l] = b.gy[l] = b.gz[l] = 0;
      b.hx[l] = k * ux[l];
      b.hy[l] = k * uy[l];
      b.hz[l] = k * uz[l];
      b.dissipated[l] = -double(b.hx[l] * b.wx[l] + b.hy[l] * b.wy[l] + b.hz[l] * b.wz[l]) * double(b.dt);
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
