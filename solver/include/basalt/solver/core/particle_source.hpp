#pragma once
// Where an insertion event puts its particles (scene/flow_spec.hpp): candidate places and radii drawn from
// a counter-based generator keyed by (seed, step, k), so that every rank draws the same candidates without
// talking and a restarted run draws what the uninterrupted one drew (no generator state to checkpoint);
// then the greedy choice among the candidates that no existing particle blocks. Free of MPI: the solver
// (simulation_flow.cpp) finds which candidates existing particles block and agrees on it over the ranks.
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <unordered_map>
#include <vector>

#include "basalt/solver/scene/flow_spec.hpp"

namespace basalt::solver {

/// A particle about to enter the run (inverse mass as the solver holds it: 1 / (density 4/3 pi r^3)).
struct NewParticle {
  std::array<double, 3> x{}, v{};
  double radius = 0, inv_mass = 0;
  std::int32_t tag = 0;
  std::int64_t id = -1;  ///< set when chosen
};

/// splitmix64's finaliser: a well-mixed 64-bit value of a 64-bit key.
inline std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
/// A uniform number in [0, 1) from a key (53 random bits).
inline double unit_random(std::uint64_t key) { return double(mix64(key) >> 11) * 0x1.0p-53; }

/// The candidates of spec's event at `step`: count x attempts spheres, each a function of (seed, step, k).
inline std::vector<NewParticle> insertion_candidates(const InsertSpec& s, std::int64_t step) {
  const auto n = static_cast<std::size_t>(s.count * s.attempts);
  std::vector<NewParticle> out(n);
  const std::uint64_t event = mix64(s.seed ^ mix64(static_cast<std::uint64_t>(step)));
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint64_t key = mix64(event + 4 * static_cast<std::uint64_t>(k));
    auto& c = out[k];
    c.radius = s.rmin + (s.rmax - s.rmin) * unit_random(key);
    c.x = s.region.sample(unit_random(key + 1), unit_random(key + 2), unit_random(key + 3), c.radius);
    c.v = s.velocity;
    c.tag = s.tag;
    c.inv_mass = 1.0 / (s.density * 4.0 / 3.0 * std::numbers::pi * std::pow(c.radius, 3));
  }
  return out;
}

/// The candidates taken, in order: each one not blocked (by an existing particle) and clear of every
/// candidate taken before it, until `count` are taken. Deterministic: the same on every rank.
inline std::vector<std::size_t> choose_candidates(const std::vector<NewParticle>& c,
                                                  const std::vector<double>& blocked, std::int64_t count) {
  std::vector<std::size_t> taken;
  if (c.empty()) return taken;
  double rmax = 0;
  for (const auto& p : c) rmax = std::max(rmax, p.radius);
  const double cell = 2 * rmax;
  const auto key = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    return (static_cast<std::uint64_t>(i) * 73856093ull) ^ (static_cast<std::uint64_t>(j) * 19349663ull) ^
           (static_cast<std::uint64_t>(k) * 83492791ull);
  };
  const auto cell_of = [&](double v) { return static_cast<std::int64_t>(std::floor(v / cell)); };
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> grid;
  for (std::size_t k = 0; k < c.size() && static_cast<std::int64_t>(taken.size()) < count; ++k) {
    if (blocked[k] != 0) continue;
    const auto& p = c[k];
    const std::int64_t ci = cell_of(p.x[0]), cj = cell_of(p.x[1]), ck = cell_of(p.x[2]);
    bool clear = true;
    for (std::int64_t i = ci - 1; i <= ci + 1 && clear; ++i)
      for (std::int64_t j = cj - 1; j <= cj + 1 && clear; ++j)
        for (std::int64_t l = ck - 1; l <= ck + 1 && clear; ++l) {
          const auto it = grid.find(key(i, j, l));
          if (it == grid.end()) continue;
          for (const auto t : it->second) {
            const auto& q = c[t];
            const double dx = p.x[0] - q.x[0], dy = p.x[1] - q.x[1], dz = p.x[2] - q.x[2];
            const double rs = p.radius + q.radius;
            if (dx * dx + dy * dy + dz * dz < rs * rs) {
              clear = false;
              break;
            }
          }
        }
    if (!clear) continue;
    taken.push_back(k);
    grid[key(ci, cj, ck)].push_back(k);
  }
  return taken;
}

}  // namespace basalt::solver
