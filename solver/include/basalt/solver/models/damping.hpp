#pragma once
// Damping, as body forces on each particle of the given tags (ESyS-Particle "LinDamping" and
// "RotDamping", and Cundall's local damping):
//   linear_damping:      F = -nu m (v - v_ref)                   (ESyS LinDampingPrms viscosity nu)
//   rotational_damping:  T = -nu I w                             (ESyS RotDampingPrms viscosity nu)
//   local_damping:       F_k -= alpha |F_k| sign(v_k), each component k of the force from every other
//                        model (non-viscous; alpha in [0, 1); Cundall 1987, as in PFC and Yade's
//                        NewtonIntegrator damping), and the same on torques with w.
// The energy they take out goes to the ledger term damping_dissipated (the power F . v over each step).
#include <array>
#include <cmath>
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
  static constexpr std::array keys{KeyDoc{"viscosity", "nu, 1/time, >= 0 (required)"},
                                   KeyDoc{"reference_velocity", "[vx, vy, vz] (default 0)"},
                                   KeyDoc{"tags", "particle tags it acts on (default: all)"}};
  static constexpr Fields reads = kVelocity | kInverseMass | kTag;
  static constexpr Fields writes = kForce;

  struct Params {
    double nu = 0;
    std::array<double, 3> v_ref{0, 0, 0};
  };
  template <class Real>
  struct Coeffs {
    Real nu, vx, vy, vz;
  };
  struct History {};

  static Params parse(TableReader& t) {
    Params p;
    p.nu = t.non_negative("viscosity");
    if (t.has("reference_velocity")) p.v_ref = t.vec3("reference_velocity");
    return p;
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {Real(p.nu), Real(p.v_ref[0]), Real(p.v_ref[1]), Real(p.v_ref[2])};
  }
  static double max_stiffness(const Params&, double) { return 0; }

  template <class Real>
  static void apply(const Coeffs<Real>& c, const BodyState<Real>& b, BodyForce<Real>& f) {
    const Real s = -c.nu * b.m;
    const Real ux = b.vx - c.vx, uy = b.vy - c.vy, uz = b.vz - c.vz;
    f.fx = s * ux;
    f.fy = s * uy;
    f.fz = s * uz;
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
  static constexpr std::array keys{KeyDoc{"viscosity", "nu, 1/time, >= 0 (required)"},
                                   KeyDoc{"tags", "particle tags it acts on (default: all)"}};
  static constexpr Fields reads = kAngularVelocity | kInverseMass | kRadius | kTag;
  static constexpr Fields writes = kTorque;

  struct Params {
    double nu = 0;
  };
  template <class Real>
  struct Coeffs {
    Real nu;
  };
  struct History {};

  static Params parse(TableReader& t) { return {t.non_negative("viscosity")}; }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {Real(p.nu)};
  }
  static double max_stiffness(const Params&, double) { return 0; }

  template <class Real>
  static void apply(const Coeffs<Real>& c, const BodyState<Real>& b, BodyForce<Real>& f) {
    const Real s = -c.nu * b.inertia;
    f.tx = s * b.wx;
    f.ty = s * b.wy;
    f.tz = s * b.wz;
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
