#pragma once
// Test model for per-contact history (not for physics): linear elastic repulsion whose stiffness
// grows with the age of the contact,
//   n = steps the pair has been touching (its History; reset to 0 when the spheres part),
//   F = K (1 + growth min(n, saturation) / saturation) (ri + rj - r),  E = F (ri + rj - r) / 2.
// A restart, a migration or a rebuild that lost or doubled a contact's age changes the forces, so
// the history tests (tests/solver/test_contact_history.cpp, io_e2e restart_history) see it.
#include <algorithm>
#include <array>
#include <string_view>

#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

struct ContactAge {
  static constexpr std::string_view name = "test_contact_age";
  static constexpr ModelKind kind = ModelKind::pair;
  static constexpr std::string_view summary =
      "test model: F = K (1 + growth min(n, saturation) / saturation) (ri + rj - r), n = steps in contact";
  static constexpr std::array keys{
      KeyDoc{"K", "stiffness, force/length, >= 0 (required)"},
      KeyDoc{"growth", "relative stiffening at saturation, >= 0 (default 0.5)"},
      KeyDoc{"saturation", "steps in contact to full stiffening, > 0 (default 100)"},
      KeyDoc{"tags", "[a, b]: pairs tagged a and b (default: all pairs)"}};
  static constexpr Fields reads = kPosition | kRadius | kId;
  static constexpr Fields writes = kForce;

  struct Params {
    double K = 0, growth = 0.5, saturation = 100;
  };
  template <class Real>
  struct Coeffs {
    Real K, growth, saturation;
  };
  struct History {
    double steps = 0;  ///< steps in contact
  };

  static Params parse(TableReader& t) {
    Params p;
    p.K = t.non_negative("K");
    p.growth = t.non_negative_or("growth", 0.5);
    if (t.has("saturation")) p.saturation = t.positive("saturation");
    return p;
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {Real(p.K), Real(p.growth), Real(p.saturation)};
  }
  static double max_stiffness(const Params& p, double) { return p.K * (1 + p.growth); }

  template <class Real>
  static void advance(const Coeffs<Real>&, History& h, Real, Real) {
    h.steps += 1;
  }
  static void apart(History& h) { h.steps = 0; }
  template <class Real>
  static double parting_energy(const Coeffs<Real>&, const History&) {
    return 0;
  }
  static History flip(const History& h) { return h; }  // an age has no orientation

  template <class Real>
  static Real force(const Coeffs<Real>& c, const History& h, Real rsum, Real r) {
    return stiffness(c, h) * (rsum - r);
  }
  template <class Real>
  static Real energy(const Coeffs<Real>& c, const History& h, Real rsum, Real r) {
    const Real d = rsum - r;
    return Real(0.5) * stiffness(c, h) * d * d;
  }

 private:
  template <class Real>
  static Real stiffness(const Coeffs<Real>& c, const History& h) {
    return c.K * (1 + c.growth * std::min(Real(h.steps), c.saturation) / c.saturation);
  }
};

}  // namespace basalt::solver
