#pragma once
// Planar walls with prescribed motion acting on owned particles through a wall model.
// Tallies the force on each wall (minus the sum of forces it puts on particles), the wall energy and
// the work walls do on the particles (the energy source the stability guard allows for).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::solver {

template <class Real, class Model>
class WallDriver {
 public:
  explicit WallDriver(const std::vector<WallSpec>& walls)
      : walls_(walls), point_(walls.size()), force_(walls.size()) {
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

  /// At a rebuild: the owned particles within reach of each wall (centre closer than radius + skin,
  /// taking the wall's tags), so that steps loop over those only.
  void rebuild(const Particles<Real>& p, double skin) {
    candidates_.resize(walls_.size());
    point_at_rebuild_ = point_;
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const auto& spec = walls_[w];
      auto& c = candidates_[w];
      c.clear();
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        const double d = (p.x[i] - point_[w][0]) * spec.normal[0] + (p.y[i] - point_[w][1]) * spec.normal[1] +
                         (p.z[i] - point_[w][2]) * spec.normal[2];
        if (d >= double(p.radius[i]) + skin) continue;
        if (!spec.tags.empty() && std::find(spec.tags.begin(), spec.tags.end(), p.tag[i]) == spec.tags.end())
          continue;
        c.push_back(static_cast<std::int32_t>(i));
      }
    }
  }

  /// Squared distance the walls moved towards their particles since the last rebuild (the same on
  /// every rank): with particle displacements, it decides the next rebuild.
  double moved2_since_rebuild() const {
    double m = 0;
    for (std::size_t w = 0; w < walls_.size() && w < point_at_rebuild_.size(); ++w) {
      const auto& n = walls_[w].normal;
      const double u = (point_[w][0] - point_at_rebuild_[w][0]) * n[0] +
                       (point_[w][1] - point_at_rebuild_[w][1]) * n[1] +
                       (point_[w][2] - point_at_rebuild_[w][2]) * n[2];
      if (u > 0) m = std::max(m, u * u);
    }
    return m;
  }

  template <bool Energy>
  double compute(Particles<Real>& p) {
    double energy = 0;
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const auto& spec = walls_[w];
      const Real nx = Real(spec.normal[0]), ny = Real(spec.normal[1]), nz = Real(spec.normal[2]);
      const Real px = Real(point_[w][0]), py = Real(point_[w][1]), pz = Real(point_[w][2]);
      double wfx = 0, wfy = 0, wfz = 0;
      for (const auto i : candidates_[w]) {
        const Real d = (p.x[i] - px) * nx + (p.y[i] - py) * ny + (p.z[i] - pz) * nz;
        const Real o = p.radius[i] - d;
        if (o <= 0) continue;
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

  std::size_t memory_bytes() const {
    std::size_t b = 0;
    for (const auto& c : candidates_) b += c.capacity() * sizeof(std::int32_t);
    return b;
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
  std::vector<std::array<double, 3>> point_at_rebuild_;
  std::vector<std::vector<std::int32_t>> candidates_;
};

}  // namespace basalt::solver
