#pragma once
// JKR adhesive elastic contact (Johnson, Kendall & Roberts 1971; the displacement-controlled branch as in
// Johnson, "Contact Mechanics", 1985, ch. 5.5): dry adhesion of fine powders, which ESyS-Particle does not
// model. With overlap d = ri + rj - r, R* = ri rj / (ri + rj), E* = E / (2 (1 - nu^2)), work of adhesion w
// (energy per area; twice the surface energy of one face), and the contact radius a from
//   d = a^2 / R* - sqrt(2 pi w a / E*),
// the force along the line of centres (positive: pushing apart) is
//   F = 4 E* a^3 / (3 R*) - sqrt(8 pi w E* a^3).
// A neck forms when the spheres touch (d = 0: a = a0 = (2 pi w R*^2 / E*)^(1/3), F = -8/9 Fc) and holds
// while the spheres are pulled apart, until d reaches d_c = -3 a_c^2 / R* with a_c = (pi w R*^2 / (8
// E*))^(1/3) (F = -5/9 Fc there); then it breaks, and the pair interacts again only when the spheres touch.
// On the way the tension peaks at the pull-off force Fc = 3/2 pi w R*. The energy is the work of F from the
// neck's formation, E(a) = G(a) - G(a0) with
//   G(a) = 8 E* a^5 / (15 R*^2) - 4 sqrt(2 pi w E*) a^(7/2) / (3 R*) + pi w a^2,
// and what a neck holds when it breaks (the hysteresis of the loop) is dissipated (ledger term
// adhesion_dissipated). Normal force only: no friction, no damping. Units: E in force/area, w in
// energy/area (force/length). History: the contact radius (0: no neck) and the energy, per pair.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string_view>

#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

struct Jkr {
  static constexpr std::string_view name = "jkr";
  static constexpr ModelKind kind = ModelKind::pair;
  static constexpr std::string_view summary =
      "JKR adhesive elastic contact: F = 4 E* a^3 / (3 R*) - sqrt(8 pi w E* a^3), necks form at touching "
      "and break at d = -3 a_c^2 / R* (pull-off force 3/2 pi w R*)";
  static constexpr std::array keys{
      KeyDoc{"E", "Young's modulus, force/area, > 0 (required)"},
      KeyDoc{"nu", "Poisson's ratio, in (-1, 0.5) (default 0.25)"},
      KeyDoc{"work_of_adhesion", "w, energy/area, > 0 (required): twice the surface energy of one face"},
      KeyDoc{"tags", "[a, b]: pairs tagged a and b (default: all pairs)"}};
  static constexpr Fields reads = kPosition | kRadius | kId;
  static constexpr Fields writes = kForce;
  static constexpr std::string_view dissipation_term = "adhesion_dissipated";

  struct Params {
    double E = 0, nu = 0.25, w = 0;
  };
  template <class Real>
  struct Coeffs {
    Real E_star;  ///< E / (2 (1 - nu^2))
    Real c2;      ///< 2 pi w / E*: d = a^2 / R* - sqrt(c2 a)
  };
  struct History {
    double a = 0;       ///< contact radius at the last real step; 0: no neck
    double energy = 0;  ///< E(a) then: lost when the neck breaks
  };

  static Params parse(TableReader& t) {
    Params p;
    p.E = t.positive("E");
    p.nu = t.number_or("nu", 0.25);
    if (!(p.nu > -1 && p.nu < 0.5)) t.fail("nu", "must be in (-1, 0.5)");
    p.w = t.positive("work_of_adhesion");
    return p;
  }
  static double e_star(const Params& p) { return p.E / (2 * (1 - p.nu * p.nu)); }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    const double es = e_star(p);
    return {Real(es), Real(2 * std::numbers::pi * p.w / es)};
  }
  /// The normal stiffness dF/dd -> 2 E* a at an overlap of 5 % of rmax between two spheres of rmax (as
  /// Hertz-Mindlin). It grows without bound just before a neck breaks (dd/da = 0 there), for one step.
  static double max_stiffness(const Params& p, double rmax) {
    return 2 * e_star(p) * std::sqrt(0.5 * rmax * 0.05 * rmax);
  }
  /// The longest neck, -d_c = 3 (pi w / (8 E*))^(2/3) R*^(1/3), grows with R*: at its largest, R* = rmax / 2.
  static double reach(const Params& p, double rmax) {
    return 3 * std::pow(std::numbers::pi * p.w / (8 * e_star(p)), 2.0 / 3.0) * std::cbrt(0.5 * rmax);
  }

  /// A pair interacts while the spheres overlap, or while its neck holds (d > d_c).
  template <class Real>
  static bool touching(const Coeffs<Real>& c, const History& h, Real ri, Real rj, Real r2) {
    const Real rsum = ri + rj;
    if (r2 < rsum * rsum) return true;
    if (!(h.a > 0)) return false;
    const Real R = ri * rj / rsum, ac = a_critical(c, R), lim = rsum + 3 * ac * ac / R;
    return r2 < lim * lim;
  }
  template <class Real>
  static void advance(const Coeffs<Real>& c, History& h, Real ri, Real rj, Real r) {
    const Real R = ri * rj / (ri + rj), a = contact_radius(c, R, ri + rj - r);
    h.a = double(a);
    h.energy = double(energy_of(c, R, a));
  }
  static void apart(History& h) { h = History{}; }
  static History flip(const History& h) { return h; }  // no orientation
  template <class Real>
  static double parting_energy(const Coeffs<Real>&, const History& h) {
    return h.energy;
  }

  template <class Real>
  static Real force(const Coeffs<Real>& c, const History& h, Real ri, Real rj, Real r) {
    const Real R = ri * rj / (ri + rj), a = h.a > 0 ? Real(h.a) : contact_radius(c, R, ri + rj - r);
    return c.E_star * (Real(4) / 3 * a * a * a / R - 2 * a * std::sqrt(c.c2 * a));
  }
  template <class Real>
  static Real energy(const Coeffs<Real>& c, const History& h, Real ri, Real rj, Real r) {
    const Real R = ri * rj / (ri + rj), a = h.a > 0 ? Real(h.a) : contact_radius(c, R, ri + rj - r);
    return energy_of(c, R, a);
  }

  /// a0: the contact radius at d = 0, where a neck forms.
  template <class Real>
  static Real a_formed(const Coeffs<Real>& c, Real R) {
    return std::cbrt(c.c2 * R * R);
  }
  /// a_c = a0 / 16^(1/3): the smallest contact radius of a neck (d is least there).
  template <class Real>
  static Real a_critical(const Coeffs<Real>& c, Real R) {
    return std::cbrt(c.c2 * R * R / 16);
  }
  /// The contact radius at overlap d (d >= d_c): Newton's method on f(a) = a^2 / R - sqrt(c2 a) - d, which
  /// is convex and increasing for a > a_c, from a start above the root (sqrt(R max(d, 0)) + a0), so the
  /// steps fall monotonically onto it; they stop when a step no longer decreases a (a pure function of
  /// its arguments: the same bits on every rank).
  template <class Real>
  static Real contact_radius(const Coeffs<Real>& c, Real R, Real d) {
    const Real ac = a_critical(c, R);
    Real a = std::sqrt(R * std::max(d, Real(0))) + a_formed(c, R);
    for (int k = 0; k < 100; ++k) {
      const Real s = std::sqrt(c.c2 * a);
      const Real f = a * a / R - s - d, df = 2 * a / R - Real(0.5) * s / a;
      const Real next = a - f / df;
      if (!(next < a)) break;
      if (!(next > ac)) return ac;
      a = next;
    }
    return a;
  }
  /// E(a) = G(a) - G(a0): the work of F since the neck formed.
  template <class Real>
  static Real energy_of(const Coeffs<Real>& c, Real R, Real a) {
    const auto G = [&](Real b) {
      return c.E_star * (Real(8) / 15 * b * b * b * b * b / (R * R) -
                         Real(4) / 3 * b * b * b * std::sqrt(c.c2 * b) / R + c.c2 * b * b / 2);
    };
    return G(a) - G(a_formed(c, R));
  }
};

}  // namespace basalt::solver
