#pragma once
// Elastic contact between a planar wall and a sphere (ESyS-Particle "NRotElasticWall"):
//   signed distance d = (x - p) . n of the centre from the wall plane (n the unit normal, pointing
//   into the particles' side); overlap o = r - d > 0:  F = k o along n, E = k o^2 / 2.
// Stiffness k = K (Basalt's default, "plain"), or k = pi r K ("esys_pi_r": what ESyS-Particle 2.3.5's
// elastic wall does in 3-D, K being its normalK). Units: K in force/length.
#include <array>
#include <numbers>
#include <string_view>

#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

struct ElasticWall {
  static constexpr std::string_view name = "elastic";
  static constexpr ModelKind kind = ModelKind::wall;
  static constexpr std::string_view summary =
      "F = k (r - d) along the wall normal, k = K or pi r K (ESyS NRotElasticWall)";
  static constexpr std::array keys{
      KeyDoc{"K", "stiffness, force/length, >= 0 (required)"},
      KeyDoc{"stiffness", "\"plain\" (k = K, default) or \"esys_pi_r\" (k = pi r K)"}};
  static constexpr Fields reads = kPosition | kRadius | kTag;
  static constexpr Fields writes = kForce;

  enum class Stiffness { plain, esys_pi_r };
  /// The value of pi ESyS-Particle's wall uses (EWallInteraction.hpp: a literal, not M_PI).
  static constexpr double kEsysPi = 3.141592654;
  struct Params {
    double K = 0;
    Stiffness stiffness = Stiffness::plain;
  };
  template <class Real>
  struct Coeffs {
    Real K;
    bool pi_r;
  };
  struct History {};

  static Params parse(TableReader& t) {
    Params p;
    p.K = t.non_negative("K");
    p.stiffness = t.choice_or("stiffness", {"plain", "esys_pi_r"}, "plain") == "esys_pi_r"
                      ? Stiffness::esys_pi_r
                      : Stiffness::plain;
    return p;
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {Real(p.K), p.stiffness == Stiffness::esys_pi_r};
  }
  static double max_stiffness(const Params& p, double rmax) {
    return p.stiffness == Stiffness::esys_pi_r ? kEsysPi * rmax * p.K : p.K;
  }

  /// Force along the wall normal on a particle of radius r overlapping the wall by o > 0.
  template <class Real>
  static Real force(const Coeffs<Real>& c, Real r, Real o) {
    return stiffness(c, r) * o;
  }
  template <class Real>
  static Real energy(const Coeffs<Real>& c, Real r, Real o) {
    return Real(0.5) * stiffness(c, r) * o * o;
  }

 private:
  template <class Real>
  static Real stiffness(const Coeffs<Real>& c, Real r) {
    return c.pi_r ? Real(kEsysPi) * r * c.K : c.K;
  }
};

}  // namespace basalt::solver
