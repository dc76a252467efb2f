#pragma once
// Loops a wall model over the walls of the scene that use it and the owned particles within reach of
// each (Walls::candidates). Tallies the force on each wall (minus the sum of forces it puts on
// particles) and the wall energy; walls act on owned particles only, so there is no ghost part.
#include <string_view>
#include <vector>

#include "basalt/solver/interactions/force_compute.hpp"

namespace basalt::solver {

template <class Real, class Model>
class WallDriver final : public ForceCompute<Real> {
 public:
  using Coeffs = typename Model::template Coeffs<Real>;

  /// Takes the scene's walls whose model is Model.
  explicit WallDriver(const std::vector<WallSpec>& walls) {
    for (std::size_t w = 0; w < walls.size(); ++w) {
      if (walls[w].model != Model::name) continue;
      index_.push_back(w);
      params_.push_back(walls[w].template params_of<Model>());
      coeffs_.push_back(Model::template coeffs<Real>(params_.back()));
    }
  }

  std::string_view model() const override { return Model::name; }
  ModelKind kind() const override { return ModelKind::wall; }
  double max_stiffness(double rmax) const override {
    double m = 0;
    for (const auto& p : params_) m = std::max(m, Model::max_stiffness(p, rmax));
    return m;
  }

  double compute(ForceState<Real>& s, Part part, bool energy, bool) override {
    if (part != Part::owned) return 0;
    return energy ? loop<true>(s.p, s.walls) : loop<false>(s.p, s.walls);
  }

 private:
  template <bool Energy>
  double loop(Particles<Real>& p, Walls& walls) const {
    double energy = 0;
    for (std::size_t k = 0; k < index_.size(); ++k) {
      const std::size_t w = index_[k];
      const auto& spec = walls.spec(w);
      const auto& c = coeffs_[k];
      const Real nx = Real(spec.normal[0]), ny = Real(spec.normal[1]), nz = Real(spec.normal[2]);
      const auto& at = walls.point(w);
      const Real px = Real(at[0]), py = Real(at[1]), pz = Real(at[2]);
      double wfx = 0, wfy = 0, wfz = 0;
      for (const auto i : walls.candidates(w)) {
        const Real d = (p.x[i] - px) * nx + (p.y[i] - py) * ny + (p.z[i] - pz) * nz;
        const Real o = p.radius[i] - d;
        if (o <= 0) continue;
        const Real f = Model::force(c, p.radius[i], o);
        p.fx[i] += f * nx;
        p.fy[i] += f * ny;
        p.fz[i] += f * nz;
        wfx -= double(f * nx);
        wfy -= double(f * ny);
        wfz -= double(f * nz);
        if constexpr (Energy) energy += double(Model::energy(c, p.radius[i], o));
      }
      walls.force(w) = {wfx, wfy, wfz};
    }
    return energy;
  }

  std::vector<std::size_t> index_;  ///< the walls this model acts through
  std::vector<typename Model::Params> params_;
  std::vector<Coeffs> coeffs_;
};

}  // namespace basalt::solver
