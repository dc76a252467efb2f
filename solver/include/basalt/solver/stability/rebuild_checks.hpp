#pragma once
// What every neighbour-list rebuild checks besides the lists (solver/src/rebuild_checks.cpp): collisions too
// short for the step (stability/impact.hpp, docs/stability.md "Contact scenes at the extremes") and the
// rounding of positions far from the origin (docs/stability.md, "Coordinates far from the origin" and
// "Energy drift over 1e7 steps"). Holds what the checks have seen and said; collective (on `comm`), warning
// from rank 0.
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "basalt/solver/core/bonds.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/interactions/force_field.hpp"
#include "basalt/solver/parallel/communicator.hpp"
#include "basalt/solver/stability/impact.hpp"

namespace basalt::solver {

template <class Real>
class RebuildChecks {
 public:
  /// What the checks read at a rebuild.
  struct State {
    const Particles<Real>& p;
    const Bonds<Real>& bonds;
    const ForceField<Real>& forces;  ///< the models (collisions), pair lists and walls
    const Comm& comm;
    std::int64_t step;
    double rmin;            ///< the smallest radius (StabilityReport::rmin)
    const char* precision;  ///< "double", "float" or "mixed" (messages)
  };
  /// The fraction of the scene's largest strain that rounding may take before lost_strain warns.
  static constexpr double kStrainLossWarn = 1e-3;

  /// For scenes with a contact model that has a closed-form collision (hertz_mindlin): the message to stop
  /// the run with (alike on every rank) when a collision, touching or ahead along straight paths, lasts
  /// fewer than kImpactSteps steps of dt, naming the pair, the impact speed, the overlap and the dt it
  /// needs; forced: a warning instead, once. Warns once when a collision's overlap passes 20 % of the
  /// smaller radius. dt_critical: the start's critical step (for the message).
  std::optional<std::string> impacts(const State& s, double dt, const std::vector<std::int64_t>& fixed_tags,
                                     bool forced, double dt_critical);
  /// Float only, until it warned: warns once when the particles have moved so far from the origin that float
  /// rounds a distance between two of the smallest to a strain above kResolutionWarn (the load check sees
  /// only the start).
  void far_positions(const State& s);
  /// Double only, until it warned: warns once when the rounding of positions, epsilon |x|max / (2 r_min),
  /// exceeds kStrainLossWarn of the largest strain seen so far, of a bond (|r - r0| / r0) or a contact
  /// (overlap / (ri + rj)). Reads positions, bonds and pair lists; where the resolution is below 1e-12
  /// (near the origin) only the positions.
  void lost_strain(const State& s);

  /// The collisions seen so far (Simulation::impacts()).
  const ImpactReport& impact_report() const { return impacts_; }

 private:
  static constexpr double kEpsilon = double(std::numeric_limits<Real>::epsilon());

  bool strain_warned_ = false;  ///< lost_strain() has warned
  double strain_max_ = 0;       ///< the largest bond or contact strain lost_strain has seen (all ranks)
  bool far_warned_ = false;     ///< far_positions() has warned
  ImpactReport impacts_;        ///< what impacts() saw
};

extern template class RebuildChecks<double>;
extern template class RebuildChecks<float>;

}  // namespace basalt::solver
