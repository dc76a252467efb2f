#pragma once
// Bonded wall (ESyS-Particle "NRotBondedWall", Model/BWallInteraction.hpp): each particle of the wall's
// bond_tags is tied to the wall by a linear spring whose rest state is the start of the run,
//   F = -k (u_p - u_w),   u_p = x - x(0), u_w = p_w(t) - p_w(0)   (full vector, not only along n),
//   E = k |u_p - u_w|^2 / 2,
// so the particle follows the wall's motion. The other particles the wall touches (its tags) feel the
// elastic wall, F = k_e (r - d) n for d < r, as in ESyS's bonded-wall group. Stiffness: k = k_e = K
// ("plain"), or ESyS's 3-D scaling "esys_pi_r": k = pi r K for the bond and k_e = pi r K for the
// elastic part, with ESyS's two literals of pi (3.1415926536 and 3.141592654). Units: K force/length.
// The driver (bonded_wall_driver.hpp) keeps each bond's rest offset x(0) - p_w(0) as history.
#include <array>
#include <string_view>

#include "basalt/solver/models/elastic_wall.hpp"
#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

struct BondedWall {
  static constexpr std::string_view name = "bonded";
  static constexpr ModelKind kind = ModelKind::wall;
  static constexpr bool bonded = true;  ///< looped by BondedWallDriver (candidates: every bonded particle)
  static constexpr std::string_view summary =
      "particles of bond_tags tied by F = -k (u_p - u_w) to the wall from the start, others elastic "
      "(ESyS NRotBondedWall)";
  static constexpr std::array keys{
      KeyDoc{"K", "stiffness, force/length, >= 0 (required)"},
      KeyDoc{"stiffness", "\"plain\" (k = K, default) or \"esys_pi_r\" (k = pi r K, as ESyS in 3-D)"},
      KeyDoc{"bond_tags", "[t, ...]: particles tied to the wall (required, at least one tag)"}};
  static constexpr Fields reads = kPosition | kRadius | kTag | kId;
  static constexpr Fields writes = kForce;

  /// ESyS-Particle 2.3.5's pi in CBondedWallInteraction (the elastic part uses ElasticWall::kEsysPi).
  static constexpr double kEsysBondPi = 3.1415926536;
  struct Params {
    double K = 0;
    bool pi_r = false;
  };
  template <class Real>
  struct Coeffs {
    Real K;
    bool pi_r;
  };
  /// The bond's rest offset x(0) - p_w(0); `bonded` = 1 marks a bond (a record is never all zero).
  struct History {
    double d0x = 0, d0y = 0, d0z = 0, bonded = 0;
  };

  static Params parse(TableReader& t) {
    Params p;
    p.K = t.non_negative("K");
    p.pi_r = t.choice_or("stiffness", {"plain", "esys_pi_r"}, "plain") == "esys_pi_r";
    return p;  // bond_tags: read by the scene into WallSpec::bond_tags (the walls' candidates need them)
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {Real(p.K), p.pi_r};
  }
  static double max_stiffness(const Params& p, double rmax) {
    return p.pi_r ? kEsysBondPi * rmax * p.K : p.K;
  }

  /// The bond's stiffness for a particle of radius r.
  template <class Real>
  static Real bond_stiffness(const Coeffs<Real>& c, Real r) {
    return c.pi_r ? Real(kEsysBondPi) * r * c.K : c.K;
  }
  /// The elastic part's stiffness (ESyS's CElasticWallInteraction inside the bonded-wall group).
  template <class Real>
  static Real elastic_stiffness(const Coeffs<Real>& c, Real r) {
    return c.pi_r ? Real(ElasticWall::kEsysPi) * r * c.K : c.K;
  }
};

}  // namespace basalt::solver
