#pragma once
// What the interaction drivers share, written once. ModelDriver: a model's groups (their Params and
// Coeffs, in scene order) and what a driver answers from the model alone (name, fields read, kind, the
// largest stiffness). ContactDriver (pair, wall, bonded-wall and mesh-wall drivers): the ledger tallies
// (energy dissipated, contacts sliding at the last real step, the step) and the contact-history handoff
// around a rebuild (save_history into pending(), history_records for output), each driver giving only
// its collect(p, out) (history_records.hpp). Also the torque of a force acting along a contact arm and
// the record of a bond that broke.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "basalt/solver/interactions/force_compute.hpp"
#include "basalt/solver/models/contract.hpp"

namespace basalt::solver {

template <class Real, class Model>
class ModelDriver : public ForceCompute<Real> {
 public:
  using Params = typename Model::Params;
  using Coeffs = typename Model::template Coeffs<Real>;

  std::string_view model() const override { return Model::name; }
  Fields reads() const override { return Model::reads; }
  ModelKind kind() const override { return Model::kind; }
  double max_stiffness(double rmax) const override {
    return largest([rmax](const Params& p) { return Model::max_stiffness(p, rmax); });
  }
  double shear_stiffness(double rmax) const override {
    return largest([rmax](const Params& p) { return basalt::solver::shear_stiffness<Model>(p, rmax); });
  }
  double rolling_stiffness() const override {
    return largest([](const Params& p) { return basalt::solver::rolling_stiffness<Model>(p); });
  }

 protected:
  /// The largest of of(p) over the groups' Params p, and 0 when none is larger (the stiffest spring or the
  /// farthest reach among the groups: what the critical step and the lists must allow for).
  template <class Of>
  double largest(Of of) const {
    double m = 0;
    for (const auto& p : params_) m = std::max(m, double(of(p)));
    return m;
  }
  /// One more group of the model (the next index in params_ and coeffs_).
  void add_group(const Params& p) {
    params_.push_back(p);
    coeffs_.push_back(Model::template coeffs<Real>(p));
  }
  /// New parameters for group k.
  void set_group(std::size_t k, const Params& p) {
    params_[k] = p;
    coeffs_[k] = Model::template coeffs<Real>(p);
  }

  std::vector<Params> params_;
  std::vector<Coeffs> coeffs_;
};

/// A contact model's driver. Driver (CRTP) gives `void collect(const Particles<Real>&, ContactRecords&)
/// const`: the records of its contacts whose history holds something.
template <class Real, class Model, class Driver>
class ContactDriver : public ModelDriver<Real, Model> {
 public:
  using History = typename Model::History;
  static constexpr bool kHistory = basalt::solver::history_bytes<Model>() > 0;
  /// The model names a ledger term for the energy it dissipates.
  static constexpr bool kDissipates = requires { Model::dissipation_term; };

  ContactDriver() { pending_.width = history_width<Model>(); }

  std::string_view dissipation_term() const override {
    if constexpr (kDissipates) return Model::dissipation_term;
    return {};
  }
  double dissipated() const override { return dissipated_; }
  void set_dissipated(double d) override { dissipated_ = d; }
  std::size_t sliding_contacts() const override { return sliding_; }
  void set_time_step(double dt) override { dt_ = Real(dt); }

  void save_history(const Particles<Real>& p) override {
    if constexpr (kHistory) driver().collect(p, pending_);
  }
  ContactRecords* pending() override { return kHistory ? &pending_ : nullptr; }
  void history_records(const Particles<Real>& p, ContactRecords& out) const override {
    if constexpr (kHistory) driver().collect(p, out);
  }
  std::size_t history_bytes() const override { return basalt::solver::history_bytes<Model>(); }

 protected:
  /// A real step's owned part starts: the contacts sliding are counted again (every loop of the step, over
  /// owned and ghost parts, adds its count).
  void start_step(Part part, bool advance) {
    if (part == Part::owned && advance) sliding_ = 0;
  }

  ContactRecords pending_;   ///< records waiting for the next rebuild (ForceCompute::pending)
  double dissipated_ = 0;    ///< this rank's share of the energy dissipated since the start
  std::size_t sliding_ = 0;  ///< contacts sliding at the last real step (each once across ranks)
  Real dt_ = 0;

 private:
  const Driver& driver() const { return static_cast<const Driver&>(*this); }
};

/// The torque s (a x F) + m on a particle from a contact force F acting at x + s a (a an arm direction, s
/// its signed length along it) with the contact's couple m.
template <class Real>
struct ArmTorque {
  Real x, y, z;
};
template <class Real>
inline ArmTorque<Real> arm_torque(Real s, Real ax, Real ay, Real az, const ContactForce<Real>& f) {
  return {s * (ay * f.fz - az * f.fy) + f.mx, s * (az * f.fx - ax * f.fz) + f.my,
          s * (ax * f.fy - ay * f.fx) + f.mz};
}

/// The record of a bond (ids a, b, group) that broke at `length` from its rest length r0 in failure mode
/// `mode`, where its spheres touch: x1 + r1 / (r1 + r2) (x2 - x1), in double whatever Real is.
template <class Real>
inline BrokenBond broken_bond(std::int64_t a, std::int64_t b, double length, double r0, std::uint8_t group,
                              std::uint8_t mode, const std::array<Real, 3>& x1, Real r1,
                              const std::array<Real, 3>& x2, Real r2) {
  const double w = double(r1) / (double(r1) + double(r2));
  return {a,
          b,
          length,
          r0,
          -1,
          group,
          mode,
          double(x1[0]) + w * (double(x2[0]) - double(x1[0])),
          double(x1[1]) + w * (double(x2[1]) - double(x1[1])),
          double(x1[2]) + w * (double(x2[2]) - double(x1[2]))};
}

}  // namespace basalt::solver
