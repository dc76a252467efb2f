#pragma once
// Where an insertion event puts its particles (scene/flow_spec.hpp): candidate places and radii drawn from
// a counter-based generator keyed by (seed, step, k), so that every rank draws the same candidates without
// talking and a restarted run draws what the uninterrupted one drew (no generator state to checkpoint);
// then the greedy choice among the candidates that no existing particle blocks. Free of MPI: the solver
// (simulation_flow.cpp) finds which candidates existing particles block and agrees on it over the ranks.
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "basalt/solver/core/sphere_mass.hpp"
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
    c.inv_mass = 1.0 / sphere_mass(s.density, c.radius);
  }
  return out;
}

/// The greedy choice among candidates: each one offered is taken when it overlaps none taken before (nor any
/// particle add()ed: newcomers of an earlier insert of the same event). A hash grid of cells `cell` wide (at
/// least the largest diameter) keeps each check to the 27 cells around. Deterministic: the same on every
/// rank.
class CandidatePicker {
 public:
  explicit CandidatePicker(double cell) : cell_(cell) {}
  /// Takes p when it overlaps nothing taken so far.
  bool try_take(const NewParticle& p) {
    const std::int64_t ci = cell_of(p.x[0]), cj = cell_of(p.x[1]), ck = cell_of(p.x[2]);
    for (std::int64_t i = ci - 1; i <= ci + 1; ++i)
      for (std::int64_t j = cj - 1; j <= cj + 1; ++j)
        for (std::int64_t l = ck - 1; l <= ck + 1; ++l) {
          const auto it = grid_.find(key(i, j, l));
          if (it == grid_.end()) continue;
          for (const auto& q : it->second) {
            const double dx = p.x[0] - q[0], dy = p.x[1] - q[1], dz = p.x[2] - q[2], rs = p.radius + q[3];
            if (dx * dx + dy * dy + dz * dz < rs * rs) return false;
          }
        }
    add(p);
    return true;
  }
  /// Takes p whatever it overlaps.
  void add(const NewParticle& p) {
    grid_[key(cell_of(p.x[0]), cell_of(p.x[1]), cell_of(p.x[2]))].push_back(
        {p.x[0], p.x[1], p.x[2], p.radius});
  }

 private:
  static std::uint64_t key(std::int64_t i, std::int64_t j, std::int64_t k) {
    return (static_cast<std::uint64_t>(i) * 73856093ull) ^ (static_cast<std::uint64_t>(j) * 19349663ull) ^
           (static_cast<std::uint64_t>(k) * 83492791ull);
  }
  std::int64_t cell_of(double v) const { return static_cast<std::int64_t>(std::floor(v / cell_)); }
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::array<double, 4>>> grid_;
};

}  // namespace basalt::solver
