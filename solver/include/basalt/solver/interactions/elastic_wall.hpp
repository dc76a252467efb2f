#pragma once
// Elastic contact between a planar wall and a sphere (ESyS-Particle "NRotElasticWall"):
//   signed distance d = (x - p) . n of the centre from the wall plane (n the unit normal, pointing
//   into the particles' side); overlap o = r - d > 0:  F = k o along n, E = k o^2 / 2.
// Stiffness k = K (Basalt's default, "plain"), or k = pi r K ("esys_pi_r": what ESyS-Particle 2.3.5's
// elastic wall does in 3-D, K being its normalK). Units: K in force/length.
#include <numbers>
#include <string_view>

#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

struct ElasticWall {
  static constexpr std::string_view type = "elastic";
  enum class Stiffness { plain, esys_pi_r };
  struct Params {
    double K = 0;
    Stiffness stiffness = Stiffness::plain;
  };

  /// Keys: K (>= 0), stiffness ("plain" | "esys_pi_r").
  static Params parse(TableReader& t) {
    Params p;
    p.K = t.non_negative("K");
    p.stiffness = t.choice_or("stiffness", {"plain", "esys_pi_r"}, "plain") == "esys_pi_r"
                      ? Stiffness::esys_pi_r
                      : Stiffness::plain;
    return p;
  }

  /// Spring constant acting on a particle of radius r.
  template <class Real>
  static Real stiffness(const Params& p, Real r) {
    return p.stiffness == Stiffness::esys_pi_r ? Real(std::numbers::pi) * r * Real(p.K) : Real(p.K);
  }
  /// Force magnitude along the wall normal for overlap o (> 0 when touching).
  template <class Real>
  static Real force(Real k, Real o) {
    return k * o;
  }
  template <class Real>
  static Real energy(Real k, Real o) {
    return Real(0.5) * k * o * o;
  }
};

}  // namespace basalt::solver
