#pragma once
// One interaction model of a scene, looped by its driver (bond_driver.hpp, pair_driver.hpp,
// wall_driver.hpp): what Simulation holds a list of, one per model the scene uses. The step calls
// each compute twice: first over what involves owned particles only (overlapping the ghost refresh
// in flight), then over what involves ghosts. Virtual calls happen a few times per step, never per
// pair: the loops inside are templates over the model.
#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>

#include "basalt/solver/core/bonds.hpp"
#include "basalt/solver/core/contact_history.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/interactions/walls.hpp"
#include "basalt/solver/models/model.hpp"
#include "basalt/solver/neighbor/verlet_list.hpp"
#include "basalt/solver/stability/impact.hpp"

namespace basalt::solver {

struct BrokenBond {
  std::int64_t a, b;
  double length, rest_length;
  std::int64_t step = -1;      ///< the step it broke at (set by the simulation)
  std::uint8_t group = 0;      ///< its interaction group: a restart at that very step restores the bond
  std::uint8_t mode = 0;       ///< how it failed (BondFailure: 0 tension, 1 shear, 2 bending, 3 torsion)
  double x = 0, y = 0, z = 0;  ///< where: the contact point of the two spheres at the break
};

/// What the force computes act on during a step.
template <class Real>
struct ForceState {
  Particles<Real>& p;
  Bonds<Real>& bonds;
  std::vector<BrokenBond>& broken;
  Walls& walls;
};

/// The rank's candidate pair lists after a rebuild (every pair some pair model takes) and which pair
/// model takes a pair (index among the scene's pair computes).
template <class Real>
struct PairLists {
  const Particles<Real>& p;
  const PairList& own;
  const PairList& ghost;
  std::size_t computes = 1;                            ///< number of pair computes
  std::function<int(std::size_t, std::size_t)> taker;  ///< pair compute taking (i, j) (computes > 1)
};

enum class Part { owned, ghost };

template <class Real>
class ForceCompute {
 public:
  virtual ~ForceCompute() = default;
  virtual std::string_view model() const = 0;
  virtual ModelKind kind() const = 0;
  /// The particle fields its model reads (models/model.hpp).
  virtual Fields reads() const { return kNoFields; }
  /// The energy-ledger term its potential energy goes to.
  virtual std::string_view energy_term() const {
    switch (kind()) {
      case ModelKind::bond:
        return "bond_potential_energy";
      case ModelKind::pair:
        return "contact_potential_energy";
      case ModelKind::wall:
        return "wall_potential_energy";
      default:
        return "body_potential_energy";
    }
  }
  /// The ledger term the energy it dissipates goes to ("" when it dissipates none).
  virtual std::string_view dissipation_term() const { return {}; }
  /// This rank's share of the energy dissipated since the start (or the last set_dissipated()).
  virtual double dissipated() const { return 0; }
  virtual void set_dissipated(double) {}
  /// Contacts that slid at the last real step (this rank's share, each contact once across ranks).
  virtual std::size_t sliding_contacts() const { return 0; }
  /// The run's time step (models that integrate over a step: tangential springs, damping).
  virtual void set_time_step(double) {}
  /// Takes new parameters for its group named g.name (between steps: a body force or a contact model changed
  /// by a script; a body force takes its tags too); false when it has no group of that name. Body and pair
  /// models.
  virtual bool reconfigure(const InteractionSpec& /*g*/) { return false; }
  /// Largest spring constant for particles up to radius rmax (critical time step).
  virtual double max_stiffness(double rmax) const = 0;
  /// Pair and wall models: the stiffest tangential spring acting at the contact point of rotating particles
  /// for radii up to rmax (0: none; models/contract.hpp, shear_stiffness).
  virtual double shear_stiffness(double /*rmax*/) const { return 0; }
  /// Pair models: how far beyond ri + rj a pair of particles up to radius rmax can interact (0: only
  /// overlapping pairs; a cohesive neck reaches further, models/contract.hpp).
  virtual double reach(double /*rmax*/) const { return 0; }
  /// Contact models with a closed-form collision (stability/impact.hpp): whether this one has it, and, at a
  /// rebuild, the collision of this rank's owned particles (touching now, or meeting along straight paths)
  /// that lasts the fewest steps of dt, with the counts of large overlaps (particles of the `fixed` tags
  /// count with an infinite mass).
  virtual bool sees_impacts() const { return false; }
  virtual CollisionSeen shortest_collision(const Particles<Real>& /*p*/, const Walls& /*walls*/,
                                           double /*dt*/, const std::vector<std::int64_t>& /*fixed*/) const {
    return {};
  }
  /// Adds forces of one part; returns the potential energy when `energy`. `advance`: a real step, so
  /// contact history moves on (a force evaluation outside the step, e.g. at start or restart, reads it).
  virtual double compute(ForceState<Real>& s, Part part, bool energy, bool advance) = 0;

  // Pair models: the lists after a rebuild, and the contact history across it.
  /// Pair compute number `index` takes its pairs from the rebuilt lists and their history from pending().
  virtual void rebuild(const PairLists<Real>&, std::size_t /*index*/) {}
  /// Wall models: the walls' candidates were rebuilt; their history comes from pending().
  virtual void rebuild_walls(const Particles<Real>&, const Walls&) {}
  /// Before a rebuild (ghosts still present): the history of listed contacts into pending().
  virtual void save_history(const Particles<Real>&) {}
  /// Records waiting for the next rebuild (carried by migration, filled by a restart); null: no history.
  virtual ContactRecords* pending() { return nullptr; }
  /// This rank's history records for output (checkpoints): every contact it lists whose history holds
  /// something, owned-ghost pairs included, so that a contact between two ranks' particles is written by
  /// both, each with its own history in its own orientation (a restart gives each rank its own back:
  /// contact_history.hpp, docs/formats.md); nothing without history.
  virtual void history_records(const Particles<Real>&, ContactRecords&) const {}
  /// Bytes of history per contact (0: none).
  virtual std::size_t history_bytes() const { return 0; }
  /// Contacts in the lists this compute loops (for the memory report).
  virtual std::size_t contacts() const { return 0; }

  // Bond models.
  /// Whether a bond of this model can break.
  virtual bool can_break() const { return false; }
  /// Rest length of a bond of group g created between radii ri, rj at distance r.
  virtual double rest_length(std::size_t /*group*/, double /*ri*/, double /*rj*/, double r) const {
    return r;
  }

  virtual std::size_t memory_bytes() const { return 0; }
};

}  // namespace basalt::solver
