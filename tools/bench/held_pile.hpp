#pragma once
// The granular pile held at rest (docs/stability.md, "A pile held for 1e7 steps"; issue 46): one geometry and
// one scene for tools/bench/pile_drift.cpp (1e7 steps) and its short test
// (tests/solver/test_bond_cascade.cpp, PileHeld, 1e5 steps), so that the test is the tool's run, shortened.
// side x side x layers spheres (radii 0.425 to 0.575, density 1) on a jittered lattice in a box (a floor and
// four side walls), hertz_mindlin pairs and walls (E = 1e5, nu = 0.25, e = 0.5: the contacts' own damping, no
// global damping; mu = 0.5), gravity 1, dt = 1e-3 (about 0.2 of the critical step). Header only, no test
// framework: the tool is built without the tests.
#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <string>

#include "basalt/io/geometry.hpp"

namespace basalt::bench {

/// A value in [-1, 1) from an integer, the same on every rank (the tests' hash_unit, tests/support).
inline double pile_hash(std::uint64_t k) {
  k += 0x9E3779B97F4A7C15ull;
  k = (k ^ (k >> 30)) * 0xBF58476D1CE4E5B9ull;
  k = (k ^ (k >> 27)) * 0x94D049BB133111EBull;
  k ^= k >> 31;
  return double(k >> 11) * 0x1.0p-53 * 2.0 - 1.0;
}

constexpr double kPileSpacing = 1.2;  // lattice spacing: the largest diameter is 1.15

/// The pile before it settles: layer by layer, ids from 1.
inline io::Geometry pile(int side, int layers) {
  io::Geometry g;
  std::int64_t id = 1;
  for (int k = 0; k < layers; ++k)
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i, ++id) {
        const auto u = static_cast<std::uint64_t>(id);
        g.add_particle(id,
                       {kPileSpacing * (i + 0.5) + 0.02 * pile_hash(3 * u),
                        kPileSpacing * (j + 0.5) + 0.02 * pile_hash(3 * u + 1), kPileSpacing * (k + 0.5)},
                       0.5 + 0.075 * pile_hash(7 * u + 5));
      }
  g.sort_by_id();
  return g;
}

inline std::string pile_wall(const char* name, std::array<double, 3> point, std::array<double, 3> normal) {
  return fmt::format(
      "[[walls]]\nname = \"{}\"\npoint = [{}, {}, {}]\nnormal = [{}, {}, {}]\ninteraction = "
      "\"hertz_mindlin\"\nE = 1.0e5\nnu = 0.25\ne = 0.5\nmu = 0.5\n",
      name, point[0], point[1], point[2], normal[0], normal[1], normal[2]);
}

/// The scene's text without its [geometry] table (the geometry is given in memory).
inline std::string pile_scene(int side, const std::string& precision) {
  const double w = kPileSpacing * side;
  return fmt::format(R"([run]
dt = 1e-3
steps = 0
skin = 0.1
precision = "{}"
[[interactions]]
type = "hertz_mindlin"
E = 1.0e5
nu = 0.25
e = 0.5
mu = 0.5
[[body_forces]]
type = "gravity"
acceleration = [0.0, 0.0, -1.0]
)",
                     precision) +
         pile_wall("floor", {0, 0, 0}, {0, 0, 1}) + pile_wall("x0", {0, 0, 0}, {1, 0, 0}) +
         pile_wall("x1", {w, 0, 0}, {-1, 0, 0}) + pile_wall("y0", {0, 0, 0}, {0, 1, 0}) +
         pile_wall("y1", {0, w, 0}, {0, -1, 0});
}

}  // namespace basalt::bench
