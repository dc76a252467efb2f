#pragma once
// The scene's planar walls as the run moves them: each wall's point at the current time, the force
// the particles put on it (this rank's share, summed by whichever wall models act on it), and the
// owned particles within reach of it since the last rebuild. Wall models (wall_driver.hpp) read
// and write these; field savers, frames and the energy guard read them.
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::solver {

class Walls {
 public:
  explicit Walls(const std::vector<WallSpec>& walls)
      : walls_(walls), point_(walls.size()), force_(walls.size()), velocity_(walls.size()) {
    for (std::size_t w = 0; w < walls.size(); ++w) point_[w] = walls[w].point;
  }

  bool empty() const { return walls_.empty(); }
  std::size_t size() const { return walls_.size(); }
  const WallSpec& spec(std::size_t w) const { return walls_[w]; }
  const std::array<double, 3>& point(std::size_t w) const { return point_[w]; }
  /// Force the particles put on wall w at the last force computation (this rank's share).
  const std::array<double, 3>& force(std::size_t w) const { return force_[w]; }
  std::array<double, 3>& force(std::size_t w) { return force_[w]; }
  /// Owned particles within reach of wall w (local indices), from the last rebuild.
  const std::vector<std::int32_t>& candidates(std::size_t w) const { return candidates_[w]; }

  /// Velocity of wall w at the time of the last move_to().
  const std::array<double, 3>& velocity(std::size_t w) const { return velocity_[w]; }

  /// Moves the walls to their positions at time t.
  void move_to(double t) {
    velocity_.resize(walls_.size());
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const auto u = walls_[w].motion.displacement_at(t);
      for (int d = 0; d < 3; ++d) point_[w][d] = walls_[w].point[d] + u[d];
      velocity_[w] = walls_[w].motion.velocity_at(t);
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
  template <class Real>
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

  std::size_t memory_bytes() const {
    std::size_t b = 0;
    for (const auto& c : candidates_) b += c.capacity() * sizeof(std::int32_t);
    return b;
  }

 private:
  std::vector<WallSpec> walls_;
  std::vector<std::array<double, 3>> point_;
  std::vector<std::array<double, 3>> force_;
  std::vector<std::array<double, 3>> velocity_;
  std::vector<std::array<double, 3>> point_at_rebuild_;
  std::vector<std::vector<std::int32_t>> candidates_;
};

}  // namespace basalt::solver
