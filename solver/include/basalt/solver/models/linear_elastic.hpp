#pragma once
// Linear elastic repulsion between touching, unbonded spheres (ESyS-Particle "NRotElastic"):
//   overlap d = ri + rj - r > 0:  F = K d pushing the centres apart, E = K d^2 / 2; no force otherwise.
// Units: K in force/length. No history (no friction): the pair list alone decides who interacts.
#include <array>
#include <string_view>

#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

struct LinearElastic {
  static constexpr std::string_view name = "linear_elastic";
  static constexpr ModelKind kind = ModelKind::pair;
  static constexpr std::string_view summary =
      "F = K (ri + rj - r) pushing touching, unbonded spheres apart (ESyS NRotElastic)";
  static constexpr std::array keys{KeyDoc{"K", "stiffness, force/length, >= 0 (required)"},
                                   KeyDoc{"tags", "[a, b]: pairs tagged a and b (default: all pairs)"}};
  static constexpr Fields reads = kPosition | kRadius | kId;
  static constexpr Fields writes = kForce;

  struct Params {
    double K = 0;
  };
  template <class Real>
  struct Coeffs {
    Real K;
  };
  struct History {};

  static Params parse(TableReader& t) { return Params{t.non_negative("K")}; }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {Real(p.K)};
  }
  static double max_stiffness(const Params& p, double) { return p.K; }

  /// Normal force magnitude for touching spheres (r < rsum), positive when it pushes apart.
  template <class Real>
  static Real force(const Coeffs<Real>& c, const History&, Real rsum, Real r) {
    return c.K * (rsum - r);
  }
  template <class Real>
  static Real energy(const Coeffs<Real>& c, const History&, Real rsum, Real r) {
    const Real d = rsum - r;
    return Real(0.5) * c.K * d * d;
  }
};

}  // namespace basalt::solver
