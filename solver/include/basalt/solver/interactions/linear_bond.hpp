#pragma once
// Linear elastic bond between two particles (ESyS-Particle "NRotBond", non-rotational):
//   F = K (r - r0) along the line of centres (attractive when stretched), E = K (r - r0)^2 / 2,
//   broken when (r - r0) > break_strain * r0 (ESyS: relative strain "breakDistance").
// Units: K in force/length (N/mm in mm-ms-N), r and r0 in length. r0 is the bond's history, set at
// start either to the initial distance (Basalt's default) or to r1 + r2 (ESyS-Particle's convention).
#include <cmath>
#include <limits>
#include <string_view>

#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

struct LinearBond {
  static constexpr std::string_view type = "linear_bond";
  enum class RestLength { initial_distance, sum_of_radii };
  struct Params {
    double K = 0;
    double break_strain = std::numeric_limits<double>::infinity();  ///< infinity: never breaks
    RestLength rest_length = RestLength::initial_distance;
  };
  struct History {
    double r0 = 0;
  };

  /// Keys: K (>= 0), break_strain (> 0, optional: unbreakable), rest_length ("initial_distance" |
  /// "sum_of_radii").
  static Params parse(TableReader& t) {
    Params p;
    p.K = t.non_negative("K");
    if (t.has("break_strain")) p.break_strain = t.positive("break_strain");
    p.rest_length =
        t.choice_or("rest_length", {"initial_distance", "sum_of_radii"}, "initial_distance") == "sum_of_radii"
            ? RestLength::sum_of_radii
            : RestLength::initial_distance;
    return p;
  }

  /// Rest length for a bond created between radii ri, rj at distance r.
  static double rest_length(const Params& p, double ri, double rj, double r) {
    return p.rest_length == RestLength::sum_of_radii ? ri + rj : r;
  }

  /// Normal force magnitude, positive when it pushes the particles apart.
  template <class Real>
  static Real force(Real K, Real r0, Real r) {
    return K * (r0 - r);
  }
  template <class Real>
  static Real energy(Real K, Real r0, Real r) {
    const Real s = r - r0;
    return Real(0.5) * K * s * s;
  }
  template <class Real>
  static bool broken(Real break_strain, Real r0, Real r) {
    return (r - r0) > break_strain * r0;
  }
};

}  // namespace basalt::solver
