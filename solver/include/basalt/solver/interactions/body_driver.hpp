#pragma once
// Loops a body-force model (a force on each particle from its own state: gravity, ...) over the owned
// particles its groups take (by tag). Ghosts get nothing: each rank applies it to its own particles.
#include <algorithm>
#include <string_view>
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
    }
  }

  std::string_view model() const override { return Model::name; }
  ModelKind kind() const override { return ModelKind::body; }
  std::string_view energy_term() const override { return Model::energy_term; }
  double max_stiffness(double) const override { return 0; }

  double compute(ForceState<Real>& s, Part part, bool energy, bool) override {
    if (part != Part::owned) return 0;
    return energy ? loop<true>(s.p) : loop<false>(s.p);
  }

 private:
  template <bool Energy>
  double loop(Particles<Real>& p) const {
    double e = 0;
    for (std::size_t g = 0; g < coeffs_.size(); ++g) {
      const auto& c = coeffs_[g];
      const auto& tags = tags_[g];
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        if (!tags.empty() && std::find(tags.begin(), tags.end(), p.tag[i]) == tags.end()) continue;
        const Real m = p.mass(i);
        const auto f = Model::force(c, m, p.x[i], p.y[i], p.z[i]);
        p.fx[i] += f[0];
        p.fy[i] += f[1];
        p.fz[i] += f[2];
        if constexpr (Energy) e += double(Model::energy(c, m, p.x[i], p.y[i], p.z[i]));
      }
    }
    return e;
  }

  std::vector<Coeffs> coeffs_;
  std::vector<TagFilter> tags_;
};

}  // namespace basalt::solver
