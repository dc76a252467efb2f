#pragma once
// The model contract, written as C++20 concepts: what a model header must declare for the registry
// (models/registry.cpp) to take it, and the rules the drivers rely on. The registry checks every model
// with check_model<Model>(); breaking a rule is a compile error whose first line says which rule.
//
// Every model (models/model.hpp lists the members):
//   name, kind, summary, keys, reads, writes; Params, parse(TableReader&), coeffs<Real>(Params),
//   Coeffs<Real> for double and float, max_stiffness(Params, rmax); History (empty when none).
//   History rules: trivially copyable, made of doubles only (checkpoints save it as float64 values).
//   Optional: shear_stiffness(Params, rmax), the stiffest tangential spring a pair or wall contact applies
//     at the contact point of rotating particles (default: none). The critical step counts it with the
//     contact point's compliance 1/m + r^2/I = 3.5/m of a solid sphere (simulation_stability.cpp); a model
//     whose tangential force does not turn the particles (ESyS's NRotFriction) declares none.
//   Optional: rolling_stiffness(Params), a rolling couple's stiffness per R*^2 (k_r / R*^2, default none):
//     it turns a sphere of radius r >= R* at w^2 <= 2.5 rolling_stiffness / m (I = 2/5 m r^2).
//   (contract::HasShearStiffness and contract::HasRollingStiffness find them.)
//
// Pair models (PairDriver, interactions/pair_driver.hpp), one of two laws:
//   scalar:    force(c, h, rsum, r) and energy(c, h, rsum, r), the force along the line of centres,
//              positive when it pushes apart; or the same with (c, h, ri, rj, r) when the law needs both
//              radii (an effective radius R* = ri rj / (ri + rj)).
//   kinematic: reads & kVelocity, contact<Advance>(c, h, ContactKinematics, ContactForce&),
//              energy(c, h, ContactKinematics) and a dissipation_term (the ledger term it fills).
//   With a History: apart(h) clears every bit of it (the driver skips pairs whose history is all zero
//   bits), flip(h) gives it as seen from the other particle, parting_energy(c, h) is the energy lost
//   with it when the pair stops interacting; a scalar law also has advance(c, h, rsum, r) (or with
//   ri, rj), called on real steps for interacting pairs before force().
//   Optional parts, found by the driver when declared:
//     touching(c, h, ri, rj, r2): whether the pair interacts (default: r2 < (ri + rj)^2, the spheres
//       overlap). A cohesive model keeps a pair that formed a neck interacting beyond touching.
//     reach(Params, rmax): how far beyond ri + rj a pair of spheres up to radius rmax can still
//       interact (default 0). The pair lists, the ghost width and the cell grid grow by the largest
//       reach of the scene's pair models.
//     dissipation_term on a scalar law: its parting energies go to that ledger term.
//     contact_lanes<Advance>(c, ContactLanes&): the kinematic law for kContactLaneWidth pairs at once
//       (models/lanes.hpp; a model with lanes keeps the default touching()).
// Bond models (BondDriver / RotBondDriver): force and energy of (c, history-free bond geometry), or
//   evaluate() for rotational bonds; broken() / failure() where bonds break; pulls_when_broken(c) (optional,
//   default false): the forces that find a bond broken still take its pull once (ESyS's NRotBond).
// Wall models (WallDriver / BondedWallDriver / MeshWallDriver): force(c, radius, overlap) and energy, or
//   the kinematic contact<Advance>(c, h, WallKinematics, ContactForce&); a wall History starts with the
//   tangential vector (the mesh walls turn it with the contact point).
// Body forces (BodyDriver): apply(c, BodyState) -> BodyForce, and optionally apply_all(c, BodyArrays&);
//   an energy_term and a dissipation_term.
#include <concepts>
#include <string_view>
#include <type_traits>

#include "basalt/solver/models/lanes.hpp"
#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

namespace contract {

template <class M>
concept Described = requires {
  { M::name } -> std::convertible_to<std::string_view>;
  { M::kind } -> std::convertible_to<ModelKind>;
  { M::summary } -> std::convertible_to<std::string_view>;
  M::keys.size();
  { M::reads } -> std::convertible_to<Fields>;
  { M::writes } -> std::convertible_to<Fields>;
};

template <class M>
concept Parameterised = requires(TableReader& t, const typename M::Params& p) {
  { M::parse(t) } -> std::same_as<typename M::Params>;
  { M::template coeffs<double>(p) } -> std::same_as<typename M::template Coeffs<double>>;
  { M::template coeffs<float>(p) } -> std::same_as<typename M::template Coeffs<float>>;
  { M::max_stiffness(p, 1.0) } -> std::convertible_to<double>;
};

/// History holds doubles only and is copied as bytes (an empty History keeps no storage).
template <class M>
concept HistoryOfDoubles = std::is_empty_v<typename M::History> ||
    (std::is_trivially_copyable_v<typename M::History> && sizeof(typename M::History) % sizeof(double) == 0);

/// What the pair driver does with a pair's history: clear it, turn it, and account for what it held.
template <class M>
concept PairHistoryRules = std::is_empty_v<typename M::History> ||
    requires(typename M::History& h, const typename M::History& ch,
             const typename M::template Coeffs<double>& c) {
  M::apart(h);
  { M::flip(ch) } -> std::same_as<typename M::History>;
  { M::parting_energy(c, ch) } -> std::convertible_to<double>;
};

/// A scalar pair law of the sum of radii, or of both radii (ScalarPairLawOfRadii).
template <class M, class Real>
concept ScalarPairLawOfSum = requires(const typename M::template Coeffs<Real>& c, typename M::History& h,
                                      Real x) {
  { M::force(c, h, x, x) } -> std::convertible_to<Real>;
  { M::energy(c, h, x, x) } -> std::convertible_to<Real>;
}
&&(std::is_empty_v<typename M::History> ||
   requires(const typename M::template Coeffs<Real>& c, typename M::History& h, Real x) {
     M::advance(c, h, x, x);
   });

template <class M, class Real>
concept ScalarPairLawOfRadii = requires(const typename M::template Coeffs<Real>& c, typename M::History& h,
                                        Real x) {
  { M::force(c, h, x, x, x) } -> std::convertible_to<Real>;
  { M::energy(c, h, x, x, x) } -> std::convertible_to<Real>;
}
&&(std::is_empty_v<typename M::History> ||
   requires(const typename M::template Coeffs<Real>& c, typename M::History& h, Real x) {
     M::advance(c, h, x, x, x);
   });

template <class M, class Real>
concept KinematicPairLaw = requires(const typename M::template Coeffs<Real>& c, typename M::History& h,
                                    const ContactKinematics<Real>& k, ContactForce<Real>& f) {
  M::template contact<true>(c, h, k, f);
  M::template contact<false>(c, h, k, f);
  { M::energy(c, h, k) } -> std::convertible_to<Real>;
  { M::dissipation_term } -> std::convertible_to<std::string_view>;
};

template <class M>
constexpr bool kinematic = (M::reads & kVelocity) != 0;

template <class M, class Real>
concept PairLaw = (kinematic<M> && KinematicPairLaw<M, Real>) ||
                  (!kinematic<M> && (ScalarPairLawOfSum<M, Real> || ScalarPairLawOfRadii<M, Real>));

/// The optional touching(): declared with the right signature, or not at all.
template <class M, class Real>
concept HasTouching = requires(const typename M::template Coeffs<Real>& c, const typename M::History& h,
                               Real x) {
  { M::touching(c, h, x, x, x) } -> std::same_as<bool>;
};
template <class M>
concept DeclaresTouching = requires {
  &M::template touching<double>;
};

/// The optional reach(): how far beyond ri + rj a pair can interact.
template <class M>
concept HasReach = requires(const typename M::Params& p) {
  { M::reach(p, 1.0) } -> std::convertible_to<double>;
};

/// The optional shear_stiffness(): the stiffest tangential spring at the contact point of rotating particles.
template <class M>
concept HasShearStiffness = requires(const typename M::Params& p) {
  { M::shear_stiffness(p, 1.0) } -> std::convertible_to<double>;
};

/// The optional rolling_stiffness(): the stiffness of a rolling couple per R*^2 (k_r / R*^2), which the
/// critical step counts for the turning of the lightest sphere (simulation_stability.cpp).
template <class M>
concept HasRollingStiffness = requires(const typename M::Params& p) {
  { M::rolling_stiffness(p) } -> std::convertible_to<double>;
};

template <class M, class Real>
concept HasContactLanes = requires(const typename M::template Coeffs<Real>& c,
                                   ContactLanes<Real, kContactLaneWidth, typename M::History>& b) {
  M::template contact_lanes<true>(c, b);
};

}  // namespace contract

/// Whether pair model M interacts at this pair: its touching(), or overlap (r2 < (ri + rj)^2).
template <class M, class Real>
inline bool pair_touching(const typename M::template Coeffs<Real>& c, const typename M::History& h, Real ri,
                          Real rj, Real r2) {
  if constexpr (contract::HasTouching<M, Real>) {
    return M::touching(c, h, ri, rj, r2);
  } else {
    const Real rsum = ri + rj;
    return r2 < rsum * rsum;
  }
}

/// How far beyond ri + rj pair model M reaches with these parameters (0 without reach()).
template <class M>
inline double pair_reach(const typename M::Params& p, double rmax) {
  if constexpr (contract::HasReach<M>)
    return M::reach(p, rmax);
  else
    return 0.0;
}

/// The stiffness of model M's rolling couple per R*^2 (0 without rolling_stiffness()).
template <class M>
inline double rolling_stiffness(const typename M::Params& p) {
  if constexpr (contract::HasRollingStiffness<M>)
    return M::rolling_stiffness(p);
  else
    return 0.0;
}

/// The stiffest tangential spring model M applies at the contact point of rotating particles (0 without
/// shear_stiffness()).
template <class M>
inline double shear_stiffness(const typename M::Params& p, double rmax) {
  if constexpr (contract::HasShearStiffness<M>)
    return M::shear_stiffness(p, rmax);
  else
    return 0.0;
}

/// Checks model M against the contract; each rule fails with its own message. Returns true.
template <class M>
constexpr bool check_model() {
  static_assert(contract::Described<M>,
                "a model declares name, kind, summary, keys, reads and writes (models/contract.hpp)");
  static_assert(contract::Parameterised<M>,
                "a model declares Params, parse(TableReader&), coeffs<Real>(Params) for double and float, "
                "and max_stiffness(Params, rmax) (models/contract.hpp)");
  static_assert(contract::HistoryOfDoubles<M>,
                "a model's History is trivially copyable and made of doubles only: checkpoints save it as "
                "float64 values (models/contract.hpp)");
  if constexpr (M::kind == ModelKind::pair) {
    static_assert(contract::PairHistoryRules<M>,
                  "a pair model with a History declares apart(h) (clearing every bit), flip(h) and "
                  "parting_energy(c, h) (models/contract.hpp)");
    static_assert(contract::PairLaw<M, double> && contract::PairLaw<M, float>,
                  "a pair model declares its law for double and float: force/energy of (c, h, rsum, r) or "
                  "(c, h, ri, rj, r) (with advance() when it has a History), or, reading velocities, "
                  "contact<Advance>, energy(c, h, k) and dissipation_term (models/contract.hpp)");
    static_assert(!contract::DeclaresTouching<M> ||
                      (contract::HasTouching<M, double> && contract::HasTouching<M, float>),
                  "a pair model's touching() is bool touching(c, h, ri, rj, r2) (models/contract.hpp)");
    static_assert(!(contract::DeclaresTouching<M> && contract::HasContactLanes<M, double>),
                  "a pair model with contact_lanes keeps the default touching(): the lanes find contacts "
                  "by overlap (models/contract.hpp)");
  }
  return true;
}

}  // namespace basalt::solver
