#pragma once
// Uniform gravity, a body force: F = m g on each particle (of the given tags), potential energy
// E = -m g . x (zero at the origin). Units: g in length/time^2 (mm/ms^2 in mm-ms-N: 9.81 m/s^2 is
// 9.81e-3 mm/ms^2).
#include <array>
#include <cmath>
#include <string_view>

#include "basalt/solver/models/lanes.hpp"
#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

struct Gravity {
  static constexpr std::string_view name = "gravity";
  static constexpr ModelKind kind = ModelKind::body;
  static constexpr std::string_view summary = "F = m g on each particle, E = -m g . x";
  static constexpr std::string_view energy_term = "gravity_potential_energy";
  static constexpr std::string_view dissipation_term = {};
  static constexpr std::array keys{KeyDoc{"acceleration", "[gx, gy, gz], length/time^2 (required)"},
                                   KeyDoc{"tags", "particle tags it acts on (default: all)"}};
  static constexpr Fields reads = kPosition | kInverseMass | kTag;
  static constexpr Fields writes = kForce;

  struct Params {
    std::array<double, 3> g{0, 0, 0};
  };
  template <class Real>
  struct Coeffs {
    Real gx, gy, gz;
  };
  struct History {};

  static Params parse(TableReader& t) {
    Params p;
    p.g = t.vec3("acceleration");
    for (double c : p.g)
      if (!std::isfinite(c)) t.fail("acceleration", "must be finite");
    return p;
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {Real(p.g[0]), Real(p.g[1]), Real(p.g[2])};
  }
  static double max_stiffness(const Params&, double) { return 0; }

  /// Force on a particle.
  template <class Real>
  static void apply(const Coeffs<Real>& c, const BodyState<Real>& b, BodyForce<Real>& f) {
    f.fx = b.m * c.gx;
    f.fy = b.m * c.gy;
    f.fz = b.m * c.gz;
  }
  /// apply() for every particle (model.hpp, BodyArrays), on the steps that do not tally the energy: the
  /// same operations (m = 1 / (1/m), then f += m g), so the same bits, in vector registers.
  template <class Real>
  BASALT_WIDE_LANES static void apply_all(const Coeffs<Real>& c, const BodyArrays<Real>& a) {
    Real* __restrict fx = a.fx;
    Real* __restrict fy = a.fy;
    Real* __restrict fz = a.fz;
    const Real* __restrict im = a.im;
#pragma GCC ivdep
    for (std::size_t i = 0; i < a.n; ++i) {
      const Real m = Real(1) / im[i];
      fx[i] += m * c.gx;
      fy[i] += m * c.gy;
      fz[i] += m * c.gz;
    }
  }
  template <class Real>
  static Real energy(const Coeffs<Real>& c, const BodyState<Real>& b) {
    return -b.m * (c.gx * b.x + c.gy * b.y + c.gz * b.z);
  }
};

}  // namespace basalt::solver
