#pragma once
// Loops a body-force model (a force on each particle from its own state: gravity, damping) over the
// owned particles its groups take (by tag). Ghosts get nothing: each rank applies it to its own
// particles. Body forces run last, in the ghost part of the step, so that a model that reads the
// force (local damping) sees every other model's share.
#include <algorithm>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "basalt/solver/interactions/force_compute.hpp"

namespace basalt::solver {

template <class Real, class Model>
class BodyDriver final : public ForceCompute<Real> {
 public:
  using Coeffs = typename Model::template Coeffs<Real>;

  /// Takes the scene's body-force groups of model Model.
  explicit BodyDriver(const std::vector<InteractionSpec>& groups) {
    for (const auto& g : groups) {
      if (g.model != Model::name) continue;
      coeffs_.push_back(Model::template coeffs<Real>(g.template params_of<Model>()));
      tags_.push_back(g.tags);
      names_.push_back(g.name);
    }
  }

  bool reconfigure(const InteractionSpec& g) override {
    for (std::size_t k = 0; k < names_.size(); ++k)
      if (names_[k] == g.name && g.model == Model::name) {
        coeffs_[k] = Model::template coeffs<Real>(g.template params_of<Model>());
        tags_[k] = g.tags;
        return true;
      }
    return false;
  }

  std::string_view model() const override { return Model::name; }
  Fields reads() const override { return Model::reads; }
  ModelKind kind() const override { return ModelKind::body; }
  std::string_view energy_term() const override { return Model::energy_term; }
  std::string_view dissipation_term() const override { return Model::dissipation_term; }
  double dissipated() const override { return dissipated_; }
  void set_dissipated(double d) override { dissipated_ = d; }
  void set_time_step(double dt) override { dt_ = Real(dt); }
  double max_stiffness(double) const override { return 0; }
  std::size_t memory_bytes() const override {
    return dissipation_.capacity() * sizeof(double) + flags_.capacity();
  }

  double compute(ForceState<Real>& s, Part part, bool energy, bool advance) override {
    if (part != Part::ghost) return 0;
    if (advance) return energy ? loop<true, true>(s.p) : loop<false, true>(s.p);
    return energy ? loop<true, false>(s.p) : loop<false, false>(s.p);
  }

 private:
  /// A model that neither reads angular velocities nor writes torques (gravity, linear damping) skips
  /// the rotational state (its inertia costs two divisions per particle).
  static constexpr bool kTurns = (Model::reads & kAngularVelocity) != 0 || (Model::writes & kTorque) != 0;

  static constexpr bool kAll = requires(const Coeffs& c, const BodyArrays<Real>& a) {
    Model::apply_all(c, a);
  };

  template <bool Energy, bool Advance>
  double loop(Particles<Real>& p) {
    // A model with a potential (gravity) takes apply_all on the steps that do not tally it.
    if constexpr (kAll && (!Energy || Model::energy_term.empty()))
      if (coeffs_.size() == 1 && tags_[0].empty()) return all<Advance>(p);
    double e = 0, d = 0;
    const bool rot = kTurns && p.with_rotation;
    BodyState<Real> b{};
    b.dt = dt_;
    for (std::size_t g = 0; g < coeffs_.size(); ++g) {
      const auto& c = coeffs_[g];
      const auto& tags = tags_[g];
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        if (!tags.empty() && std::find(tags.begin(), tags.end(), p.tag[i]) == tags.end()) continue;
        b.m = p.mass(i);
        b.im = p.inv_mass[i];
        b.x = p.x[i], b.y = p.y[i], b.z = p.z[i];
        b.vx = p.vx[i], b.vy = p.vy[i], b.vz = p.vz[i];
        b.fx = p.fx[i], b.fy = p.fy[i], b.fz = p.fz[i];
        if (rot) {
          b.inertia = Real(1) / p.inverse_inertia(i);
          b.wx = p.wx[i], b.wy = p.wy[i], b.wz = p.wz[i];
          b.tx = p.tx[i], b.ty = p.ty[i], b.tz = p.tz[i];
        }
        BodyForce<Real> f;
        Model::apply(c, b, f);
        p.fx[i] += f.fx;
        p.fy[i] += f.fy;
        p.fz[i] += f.fz;
        if (rot) {
          p.tx[i] += f.tx;
          p.ty[i] += f.ty;
          p.tz[i] += f.tz;
        }
        if constexpr (Advance) d += f.dissipated;
        if constexpr (Energy) e += double(Model::energy(c, b));
      }
    }
    dissipated_ += d;
    return e;
  }

  /// loop() for a model with apply_all and one group taking every particle: the same arithmetic per
  /// particle as apply(), the dissipation added in particle order.
  template <bool Advance>
  double all(Particles<Real>& p) {
    const bool rot = kTurns && p.with_rotation;
    if (!rot && kTurns) return 0;  // (a turning model on particles that do not turn)
    const std::size_t n = p.n_owned;
    constexpr bool kDissipates = !Model::dissipation_term.empty();
    if constexpr (kDissipates) {
      dissipation_.resize(n);
      flags_.resize(n);
    }
    BodyArrays<Real> a;
    a.n = n;
    a.dt = dt_;
    a.im = p.inv_mass.data(), a.radius = p.radius.data();
    a.vx = p.vx.data(), a.vy = p.vy.data(), a.vz = p.vz.data();
    a.fx = p.fx.data(), a.fy = p.fy.data(), a.fz = p.fz.data();
    if (rot) {
      a.wx = p.wx.data(), a.wy = p.wy.data(), a.wz = p.wz.data();
      a.tx = p.tx.data(), a.ty = p.ty.data(), a.tz = p.tz.data();
    }
    a.dissipated = dissipation_.data();
    a.flag = flags_.data();
    Model::apply_all(coeffs_[0], a);
    if constexpr (Advance && kDissipates) {
      double d = 0;
      for (std::size_t i = 0; i < n; ++i) d += dissipation_[i];
      dissipated_ += d;
    }
    return 0;
  }

  std::vector<double> dissipation_;  ///< apply_all's energies per particle
  std::vector<std::uint8_t> flags_;  ///< apply_all's scratch
  std::vector<Coeffs> coeffs_;
  std::vector<TagFilter> tags_;
  std::vector<std::string> names_;  ///< each group's name (reconfigure)
  double dissipated_ = 0;
  Real dt_ = 0;
};

}  // namespace basalt::solver
