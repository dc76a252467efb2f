#pragma once
// Planar walls with prescribed motion acting on owned particles through a wall model.
// Tallies the force on each wall (minus the sum of forces it puts on particles), the wall energy and
// the work walls do on the particles (the energy source the stability guard allows for).
#include <array>
#include <cmath>
#include <vector>

#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::solver {

template <class Real, class Model>
class WallDriver {
 public:
  explicit WallDriver(const std::vector<WallSpec>& walls) : walls_(walls), point_(walls.size()), force_(walls.size()) {
    for (std::size_t w = 0; w < walls.size(); ++w) point_[w] = walls[w].point;
  }

  bool empty() const { return walls_.empty(); }
  std::size_t size() const { return walls_.size(); }
  const WallSpec& spec(std::size_t w) const { return walls_[w]; }
  const std::array<double, 3>& point(std::size_t w) const { return point_[w]; }
  /// Force the particles put on wall w at the last compute() (this rank's share).
  const std::array<double, 3>& force(std::size_t w) const { return force_[w]; }

  /// Moves the walls to their positions at time t.
  void move_to(double t) {
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const auto u = walls_[w].motion.displacement_at(t);
      for (int d = 0; d < 3; ++d) point_[w][d] = walls_[w].point[d] + u[d];
    }
  }

  /// Power the walls put into the particles at time t (this rank's share): -F_wall . v_wall.
  double power(double t) const {
    double pw = 0;
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const auto v = walls_[w].motion.velocity_at(t);
      pw -= force_[w][0] * v[0] + force_[w][1] * v[1] + force_[w][2] * v[2];
    }
    return pw;
  }

  template <bool Energy>
  double compute(Particles<Real>& p) {
    double energy = 0;
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const auto& spec = walls_[w];
      const Real nx = Real(spec.normal[0]), ny = Real(spec.normal[1]), nz = Real(spec.normal[2]);
      const Real px = Real(point_[w][0]), py = Real(point_[w][1]), pz = Real(point_[w][2]);
      const bool all_tags = spec.tags.empty();
      double wfx = 0, wfy = 0, wfz = 0;
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        const Real d = (p.x[i] - px) * nx + (p.y[i] - py) * ny + (p.z[i] - pz) * nz;
        const Real o = p.radius[i] - d;
        if (o <= 0) continue;
        if (!all_tags && std::find(spec.tags.begin(), spec.tags.end(), p.tag[i]) == spec.tags.end()) continue;
        const Real k = Model::stiffness(spec.params, p.radius[i]);
        const Real f = Model::force(k, o);
        p.fx[i] += f * nx;
        p.fy[i] += f * ny;
        p.fz[i] += f * nz;
        wfx -= double(f * nx);
        wfy -= double(f * ny);
        wfz -= double(f * nz);
        if constexpr (Energy) energy += double(Model::energy(k, o));
      }
      force_[w] = {wfx, wfy, wfz};
    }
    return energy;
  }

  Real max_stiffness(Real rmax) const {
    Real m = 0;
    for (const auto& w : walls_) m = std::max(m, Model::stiffness(w.params, rmax));
    return m;
  }

 private:
  std::vector<WallSpec> walls_;
  std::vector<std::array<double, 3>> point_;
  std::vector<std::array<double, 3>> force_;
};

}  // namespace basalt::solver
