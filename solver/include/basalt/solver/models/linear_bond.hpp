#pragma once
// Linear elastic bond between two particles (ESyS-Particle "NRotBond", non-rotational):
//   F = K (r - r0) along the line of centres (attractive when stretched), E = K (r - r0)^2 / 2,
//   broken when (r - r0) > break_strain * r0 (ESyS: relative strain "breakDistance"). The forces that find a
//   bond broken leave it out (Basalt), or, with convention = "esys", still take its pull once, as ESyS's
//   NRotBond does (it applies the force, then finds the bond broken from the same distance: docs/esys.md).
// Units: K in force/length (N/mm in mm-ms-N), r and r0 in length. r0 is the bond's history (kept by the
// bond store, Bonds::r0), set at start either to the initial distance (Basalt's default) or to r1 + r2
// (ESyS-Particle's convention).
#include <array>
#include <cmath>
#include <limits>
#include <string_view>

#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

struct LinearBond {
  static constexpr std::string_view name = "linear_bond";
  static constexpr ModelKind kind = ModelKind::bond;
  static constexpr std::string_view summary =
      "F = K (r - r0) along the line of centres, breaks at (r - r0) > break_strain r0 (ESyS NRotBond)";
  static constexpr std::array keys{
      KeyDoc{"K", "stiffness, force/length, >= 0 (required)"},
      KeyDoc{"break_strain", "relative stretch at which the bond breaks, > 0 (default: never)"},
      KeyDoc{"rest_length", "\"initial_distance\" (default) or \"sum_of_radii\" (ESyS)"},
      KeyDoc{"convention",
             "\"basalt\" (default) or \"esys\": a bond found broken still pulls in that step's forces"},
      KeyDoc{"tags", "[a, b]: bonds between particles tagged a and b (default: all)"},
      KeyDoc{"bond_tag", "the geometry's bond tag this group takes (default: all)"}};
  static constexpr Fields reads = kPosition | kId;
  static constexpr Fields writes = kForce;

  enum class RestLength { initial_distance, sum_of_radii };
  struct Params {
    double K = 0;
    double break_strain = std::numeric_limits<double>::infinity();  ///< infinity: never breaks
    RestLength rest_length = RestLength::initial_distance;
    bool pulls_when_broken = false;  ///< convention = "esys"
  };
  template <class Real>
  struct Coeffs {
    Real K, break_strain;
    bool pulls_when_broken;
  };
  struct History {};  // the rest length lives in the bond store

  static Params parse(TableReader& t) {
    Params p;
    p.K = t.non_negative("K");
    if (t.has("break_strain")) p.break_strain = t.positive("break_strain");
    p.rest_length =
        t.choice_or("rest_length", {"initial_distance", "sum_of_radii"}, "initial_distance") == "sum_of_radii"
            ? RestLength::sum_of_radii
            : RestLength::initial_distance;
    p.pulls_when_broken = t.choice_or("convention", {"basalt", "esys"}, "basalt") == "esys";
    return p;
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {Real(p.K),
            std::isfinite(p.break_strain) ? Real(p.break_strain) : std::numeric_limits<Real>::infinity(),
            p.pulls_when_broken};
  }
  static double max_stiffness(const Params& p, double) { return p.K; }
  static bool breakable(const Params& p) { return std::isfinite(p.break_strain); }

  /// Rest length for a bond created between radii ri, rj at distance r.
  static double rest_length(const Params& p, double ri, double rj, double r) {
    return p.rest_length == RestLength::sum_of_radii ? ri + rj : r;
  }

  /// Normal force magnitude, positive when it pushes the particles apart.
  template <class Real>
  static Real force(const Coeffs<Real>& c, Real r0, Real r) {
    return c.K * (r0 - r);
  }
  template <class Real>
  static Real energy(const Coeffs<Real>& c, Real r0, Real r) {
    const Real s = r - r0;
    return Real(0.5) * c.K * s * s;
  }
  template <class Real>
  static bool broken(const Coeffs<Real>& c, Real r0, Real r) {
    return (r - r0) > c.break_strain * r0;
  }
  /// The forces that find the bond broken still take its pull (once: it is gone from the next step).
  template <class Real>
  static bool pulls_when_broken(const Coeffs<Real>& c) {
    return c.pulls_when_broken;
  }
};

}  // namespace basalt::solver
