#pragma once
// The time integrator of a run: velocity Verlet (or symplectic Euler) over the owned particles, with the
// state that lives between steps: the two kicks for the run's dt, a second half-kick deferred into the
// next step's pass, forces zeroed by that pass, and the kinetic energy the last kick computed.
//
//   first_half():  [deferred kick h2] kick h1, zero forces, drift dt     (one pass over memory)
//   ...forces...
//   second_half(): kick h2, now or deferred to the next first_half()
//
// A deferred kick gives the same bits as one made at once (kick_kick_zero_drift makes both in order);
// it saves a pass when nothing reads the velocities in between (the caller says so).
#include <optional>

#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/integrate/integrators.hpp"

namespace basalt::solver {

template <class Real>
class VelocityVerlet {
 public:
  /// The run's step; symplectic_euler: the whole kick before the drift, none after (ESyS-Particle's scheme).
  void configure(double dt, bool symplectic_euler) {
    dt_ = Real(dt);
    kick1_ = Real(symplectic_euler ? dt : dt / 2);
    kick2_ = Real(symplectic_euler ? 0.0 : dt / 2);
  }

  /// The step's first pass: a deferred second half-kick, the first half-kick, zeroed forces, the drift
  /// (and the rotations). Returns the largest squared displacement since the skin reference (inf when a
  /// position went non-finite): the rebuild criterion.
  double first_half(Particles<Real>& p) {
    ke_fresh_ = false;
    const double moved2 =
        pending_ ? kick_kick_zero_drift(p, kick2_, kick1_, dt_) : kick_zero_drift(p, kick1_, dt_);
    if (p.with_rotation) {
      if (pending_)
        rotate_kick_kick_zero_drift(p, kick2_, kick1_, dt_);
      else
        rotate_kick_zero_drift(p, kick1_, dt_);
    }
    pending_ = false;
    zeroed_ = true;
    return moved2;
  }

  /// Whether the forces are already zero (first_half, or a caller that set them: mark_zeroed()); clears it.
  /// The force computation adds onto zeroed forces.
  bool take_zeroed() {
    const bool z = zeroed_;
    zeroed_ = false;
    return z;
  }
  void mark_zeroed() { zeroed_ = true; }

  /// The second half-kick: left for the next first_half() when `defer`, else made now, computing this
  /// rank's kinetic energy in the same pass when `with_energy` (kinetic_energy() then has it).
  void second_half(Particles<Real>& p, bool defer, bool with_energy) {
    if (kick2_ == Real(0)) return;
    if (defer) {
      pending_ = true;
      return;
    }
    if (p.with_rotation) rotate_kick(p, kick2_);
    if (with_energy) {
      ke_local_ = kick_energy(p, kick2_);
      ke_fresh_ = true;
    } else {
      kick(p, kick2_);
    }
  }

  /// Makes a deferred second half-kick now (the run's way out, whatever the way).
  void settle(Particles<Real>& p) {
    if (!pending_) return;
    if (p.with_rotation) rotate_kick(p, kick2_);
    kick(p, kick2_);
    pending_ = false;
  }

  /// This rank's translational kinetic energy computed by the last second half-kick, if it computed one
  /// and nothing changed the particles since (forget_energy()).
  std::optional<double> kinetic_energy() const { return ke_fresh_ ? std::optional(ke_local_) : std::nullopt; }
  void forget_energy() { ke_fresh_ = false; }

 private:
  Real dt_ = 0, kick1_ = 0, kick2_ = 0;
  bool pending_ = false;   ///< the last step's second half-kick waits for the next first_half()
  bool zeroed_ = false;    ///< the forces are zero (set by first_half or mark_zeroed)
  bool ke_fresh_ = false;  ///< ke_local_ is the kinetic energy after the last second half-kick
  double ke_local_ = 0;
};

}  // namespace basalt::solver
