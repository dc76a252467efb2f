#pragma once
// The shortest collision a contact model sees at a neighbour-list rebuild (docs/stability.md, "Contact
// scenes at the extremes"). A velocity-Verlet step resolves a collision only if it takes many steps: a
// Hertz collision of duration t_c taken in a few steps comes out with the wrong restitution and overlap,
// and its duration shrinks with the impact speed (t_c ~ v^-1/5), which no critical step of the start can
// know. So at each rebuild each model with a closed-form collision (hertz_mindlin, pairs and walls) reports
// the pair whose collision, now or ahead, lasts the fewest steps of dt, and the run stops below
// kImpactSteps (or warns once when forced).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace basalt::solver {

/// Fewer steps per collision than this are refused (a restitution error of order 1e-2 and more,
/// docs/stability.md).
inline constexpr double kImpactSteps = 10;

/// A collision by its model's closed form (Model::collision): the impact speed, the largest overlap and
/// the duration.
struct Collision {
  double speed = 0, overlap = 0, duration = 0;
};

/// One collision, by the closed form of its model: of particles id a and b (b = -1 against wall number
/// `wall`).
struct CollisionSeen {
  double steps = std::numeric_limits<double>::infinity();  ///< duration / dt
  double speed = 0;    ///< normal impact speed (for a contact already touching: the speed of the same energy)
  double overlap = 0;  ///< largest overlap the collision reaches
  double duration = 0;  ///< of the whole collision (contact to separation)
  double ra = 0, rb = 0;
  std::int64_t a = -1, b = -1;
  int wall = -1;
  /// Collisions seen whose largest overlap passes 5 % and 20 % of the smaller radius, and the largest
  /// overlap / smaller radius of them all.
  std::int64_t above5 = 0, above20 = 0;
  double deepest = 0;

  /// Keeps the shorter collision, and counts the overlaps of `o`.
  void merge(const CollisionSeen& o) {
    above5 += o.above5;
    above20 += o.above20;
    deepest = deepest > o.deepest ? deepest : o.deepest;
    if (o.steps < steps) {
      const auto a5 = above5, a20 = above20;
      const double deep = deepest;
      *this = o;
      above5 = a5, above20 = a20, deepest = deep;
    }
  }
  /// Counts one collision's overlap against radius r.
  void count(double overlap_max, double r) {
    above5 += overlap_max > 0.05 * r;
    above20 += overlap_max > 0.2 * r;
    deepest = deepest > overlap_max / r ? deepest : overlap_max / r;
  }
  /// Replaces the collision by c of particles a and b (radii ra, rb), the counts kept.
  void set(const Collision& c, double dt, double r_a, double r_b, std::int64_t id_a, std::int64_t id_b,
           int w) {
    steps = c.duration / dt, speed = c.speed, overlap = c.overlap, duration = c.duration;
    ra = r_a, rb = r_b, a = id_a, b = id_b, wall = w;
  }
};

/// Whether a particle of tag t is fixed (particles.fixed_tags): its mass counts as infinite.
inline bool fixed_tag(const std::vector<std::int64_t>& fixed, std::int64_t t) {
  return !fixed.empty() && std::find(fixed.begin(), fixed.end(), t) != fixed.end();
}

/// Two spheres, d = x_i - x_j apart with relative velocity u = v_i - v_j, and the sum of their radii:
/// touching, the overlap and the normal speed of approach now (true even while they part: the contact's
/// energy counts); apart, the normal speed at which their straight paths bring them rsum apart (false when
/// they part or miss).
inline bool approach(const double d[3], const double u[3], double rsum, double& vn, double& overlap) {
  const double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  const double du = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
  if (r2 < rsum * rsum) {
    const double r = std::sqrt(r2);
    overlap = rsum - r;
    vn = r > 0 ? -du / r : 0.0;
    return true;
  }
  overlap = 0;
  const double uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
  if (!(du < 0) || !(uu > 0)) return false;
  const double disc = du * du - uu * (r2 - rsum * rsum);
  if (!(disc >= 0)) return false;
  const double t = (-du - std::sqrt(disc)) / uu;  // the first time they are rsum apart
  vn = -((d[0] + t * u[0]) * u[0] + (d[1] + t * u[1]) * u[1] + (d[2] + t * u[2]) * u[2]) / rsum;
  return vn > 0;
}

/// What the run has seen (Simulation::impacts()): the collision of fewest steps at any rebuild, the most
/// collisions at one rebuild above 5 % and 20 % of a radius, and the deepest (overlap / smaller radius).
struct ImpactReport {
  CollisionSeen shortest;
  std::int64_t above5 = 0, above20 = 0;
  double deepest = 0;
  std::int64_t checks = 0;  ///< rebuilds at which it looked
  bool warned = false, deep_warned = false;
};

}  // namespace basalt::solver
