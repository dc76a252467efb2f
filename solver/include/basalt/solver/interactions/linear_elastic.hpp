#pragma once
// Linear elastic repulsion between touching, unbonded spheres (ESyS-Particle "NRotElastic"):
//   overlap d = ri + rj - r > 0:  F = K d pushing the centres apart, E = K d^2 / 2; no force otherwise.
// Units: K in force/length. No history (no friction): the pair list alone decides who interacts.
#include <string_view>

#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

struct LinearElastic {
  static constexpr std::string_view type = "linear_elastic";
  struct Params {
    double K = 0;
  };

  /// Keys: K (>= 0).
  static Params parse(TableReader& t) { return Params{t.non_negative("K")}; }

  /// True when the spheres touch (r^2 < (ri + rj)^2).
  template <class Real>
  static bool touching(Real r2, Real rsum) {
    return r2 < rsum * rsum;
  }
  /// Normal force magnitude, positive when it pushes apart (r < rsum).
  template <class Real>
  static Real force(Real K, Real rsum, Real r) {
    return K * (rsum - r);
  }
  template <class Real>
  static Real energy(Real K, Real rsum, Real r) {
    const Real d = rsum - r;
    return Real(0.5) * K * d * d;
  }
};

}  // namespace basalt::solver
