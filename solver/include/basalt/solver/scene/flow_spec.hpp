#pragma once
// Particles entering and leaving a run (docs/scenes.md, "Insertion and deletion"): [[insert]] pours
// `count` new spheres into a region every `every` steps, with radii drawn uniformly from a range, placed
// where they overlap nothing; [[delete]] takes the particles out of a region (an outlet) every `every`
// steps. Free of MPI: the solver decides which candidates fit (solver/src/simulation_flow.cpp).
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

/// A box [lo, hi] or a cylinder (base centre, unit axis, radius, length along the axis).
struct Region {
  enum class Shape { box, cylinder };
  Shape shape = Shape::box;
  std::array<double, 3> lo{0, 0, 0}, hi{0, 0, 0};      ///< box
  std::array<double, 3> base{0, 0, 0}, axis{0, 0, 1};  ///< cylinder
  double radius = 0, length = 0;                       ///< cylinder

  /// Whether the point x lies inside.
  bool contains(const std::array<double, 3>& x) const { return inset_contains(x, 0); }
  /// Whether a sphere of radius r centred at x lies wholly inside.
  bool inset_contains(const std::array<double, 3>& x, double r) const {
    if (shape == Shape::box) {
      for (std::size_t d = 0; d < 3; ++d)
        if (!(x[d] >= lo[d] + r && x[d] <= hi[d] - r)) return false;
      return true;
    }
    const std::array<double, 3> q{x[0] - base[0], x[1] - base[1], x[2] - base[2]};
    const double along = q[0] * axis[0] + q[1] * axis[1] + q[2] * axis[2];
    if (!(along >= r && along <= length - r)) return false;
    const double off2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - along * along;
    return off2 <= (radius - r) * (radius - r) && r <= radius;
  }
  /// A point for u in [0, 1)^3, uniform over the region shrunk by r on every side (a sphere of radius r
  /// centred there lies inside).
  std::array<double, 3> sample(double u0, double u1, double u2, double r) const {
    if (shape == Shape::box)
      return {lo[0] + r + u0 * (hi[0] - lo[0] - 2 * r), lo[1] + r + u1 * (hi[1] - lo[1] - 2 * r),
              lo[2] + r + u2 * (hi[2] - lo[2] - 2 * r)};
    // Two unit vectors normal to the axis, then a uniform point of the disc and one along the axis.
    const std::array<double, 3> a = axis;
    const std::array<double, 3> t =
        std::abs(a[0]) < 0.9 ? std::array<double, 3>{1, 0, 0} : std::array<double, 3>{0, 1, 0};
    std::array<double, 3> e1{a[1] * t[2] - a[2] * t[1], a[2] * t[0] - a[0] * t[2], a[0] * t[1] - a[1] * t[0]};
    const double n1 = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (auto& c : e1) c /= n1;
    const std::array<double, 3> e2{a[1] * e1[2] - a[2] * e1[1], a[2] * e1[0] - a[0] * e1[2],
                                   a[0] * e1[1] - a[1] * e1[0]};
    const double rho = (radius - r) * std::sqrt(u0), phi = 2 * std::numbers::pi * u1;
    const double h = r + u2 * (length - 2 * r), c1 = rho * std::cos(phi), c2 = rho * std::sin(phi);
    return {base[0] + h * a[0] + c1 * e1[0] + c2 * e2[0], base[1] + h * a[1] + c1 * e1[1] + c2 * e2[1],
            base[2] + h * a[2] + c1 * e1[2] + c2 * e2[2]};
  }
  /// The same region in a frame whose origin is at o (mixed precision: scene/frame_origin.hpp).
  void shift(const std::array<double, 3>& o) {
    for (std::size_t d = 0; d < 3; ++d) {
      lo[d] -= o[d];
      hi[d] -= o[d];
      base[d] -= o[d];
    }
  }
  /// The axis-aligned box around the region.
  std::array<std::array<double, 3>, 2> bounds() const {
    if (shape == Shape::box) return {lo, hi};
    std::array<std::array<double, 3>, 2> b{};
    for (std::size_t d = 0; d < 3; ++d) {
      const double ends[2] = {base[d], base[d] + length * axis[d]};
      const double reach = radius * std::sqrt(std::max(0.0, 1 - axis[d] * axis[d]));
      b[0][d] = std::min(ends[0], ends[1]) - reach;
      b[1][d] = std::max(ends[0], ends[1]) + reach;
    }
    return b;
  }
};

/// One [[insert]] entry: `count` spheres per event, events at steps start, start + every, ... before stop.
struct InsertSpec {
  std::string name;
  Region region;
  double rmin = 0, rmax = 0;  ///< radii uniform in [rmin, rmax]
  double density = 0;         ///< mass = density 4/3 pi r^3 (the scene's material.density by default)
  std::int64_t count = 0;     ///< particles asked per event (fewer when the region has no room)
  std::int64_t every = 1;
  std::int64_t start = 0;  ///< the first event's step (0: the first step's; events happen as a step begins)
  std::int64_t stop = std::numeric_limits<std::int64_t>::max();  ///< no event at or after this step
  std::array<double, 3> velocity{0, 0, 0};
  std::int32_t tag = 0;
  std::uint64_t seed = 1;
  std::int64_t attempts = 20;  ///< candidate places tried per particle asked
  /// Whether an event falls at step s (the step about to be made starts with it).
  bool due(std::int64_t s) const {
    return count > 0 && s >= start && s < stop && (s - start) % every == 0;
  }
};

/// One [[delete]] entry: the particles (of `tags`, or all) whose centre is inside the region are taken
/// out of the run every `every` steps.
struct DeleteSpec {
  std::string name;
  Region region;
  std::int64_t every = 1;
  std::vector<std::int64_t> tags;
  bool due(std::int64_t s) const { return s > 0 && s % every == 0; }
};

/// The region of t (keys `box = { min, max }` or `cylinder = { base, axis, radius, length }`).
Region parse_region(TableReader& t);
/// One [[insert]] table; `density` is the scene's (the default).
InsertSpec parse_insert(TableReader& t, double density);
/// One [[delete]] table.
DeleteSpec parse_delete(TableReader& t);

}  // namespace basalt::solver
