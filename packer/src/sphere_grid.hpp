#pragma once
// A uniform cell grid over the placed spheres for overlap queries (cell side ~ rmax).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "basalt/packer/pack.hpp"
#include "basalt/packer/random.hpp"
#include "basalt/packer/vec3.hpp"
#include "basalt/packer/volume.hpp"

namespace basalt::packer::detail {

class SphereGrid {
 public:
  SphereGrid(const Bounds& b, double rmax) : lo_(b.lo), reach_(rmax) {
    double extent = std::max({b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2]});
    // Cell side rmax, but never more than ~2^24 cells (memory), never less than rmax.
    cell_ = std::max(rmax, extent / 256.0);
    const double pad = 2 * rmax;
    for (int k = 0; k < 3; ++k) {
      lo_[k] = b.lo[k] - pad;
      n_[k] = std::max(1, static_cast<int>(std::ceil((b.hi[k] - b.lo[k] + 2 * pad) / cell_)));
    }
    cells_.resize(static_cast<std::size_t>(n_[0]) * n_[1] * n_[2]);
  }

  /// True when a sphere (c, r) would overlap a placed one by more than tol.
  bool overlaps(const Vec3& c, double r, double tol) const {
    int a[3], z[3];
    range(c, r + reach_, a, z);
    for (int k = a[2]; k <= z[2]; ++k)
      for (int j = a[1]; j <= z[1]; ++j)
        for (int i = a[0]; i <= z[0]; ++i)
          for (const auto& e : cells_[index(i, j, k)]) {
            const double lim = r + e.r - tol;
            const double dx = c[0] - e.x, dy = c[1] - e.y, dz = c[2] - e.z;
            if (dx * dx + dy * dy + dz * dz < lim * lim && lim > 0) return true;
          }
    return false;
  }

  /// True when c lies inside a sphere stored in c's own cell (a cheap first test for random probes).
  bool inside_home_cell(const Vec3& c) const {
    for (const auto& e : cells_[index(coord(c[0], 0), coord(c[1], 1), coord(c[2], 2))]) {
      const double dx = c[0] - e.x, dy = c[1] - e.y, dz = c[2] - e.z;
      if (dx * dx + dy * dy + dz * dz < e.r * e.r) return true;
    }
    return false;
  }

  /// Distance from c to the surface of the nearest placed sphere, or `reach` when none is nearer.
  double clearance(const Vec3& c, double reach) const {
    int a[3], z[3];
    range(c, reach + reach_, a, z);
    double best = reach;
    for (int k = a[2]; k <= z[2]; ++k)
      for (int j = a[1]; j <= z[1]; ++j)
        for (int i = a[0]; i <= z[0]; ++i)
          for (const auto& e : cells_[index(i, j, k)]) {
            const double dx = c[0] - e.x, dy = c[1] - e.y, dz = c[2] - e.z;
            best = std::min(best, std::sqrt(dx * dx + dy * dy + dz * dz) - e.r);
          }
    return best;
  }

  void add(const Vec3& c, double r) {
    cells_[index(coord(c[0], 0), coord(c[1], 1), coord(c[2], 2))].push_back({c[0], c[1], c[2], r});
  }

 private:
  struct Entry {
    double x, y, z, r;
  };
  int coord(double x, int k) const {
    return std::clamp(static_cast<int>(std::floor((x - lo_[k]) / cell_)), 0, n_[k] - 1);
  }
  void range(const Vec3& c, double reach, int a[3], int z[3]) const {
    for (int k = 0; k < 3; ++k) {
      a[k] = coord(c[k] - reach, k);
      z[k] = coord(c[k] + reach, k);
    }
  }
  std::size_t index(int i, int j, int k) const {
    return (static_cast<std::size_t>(k) * n_[1] + j) * n_[0] + i;
  }
  Vec3 lo_;
  double reach_;
  double cell_ = 1;
  int n_[3] = {1, 1, 1};
  std::vector<std::vector<Entry>> cells_;
};

/// What the void filler works on (packer/src/void_filler.cpp, the one file that uses CGAL's triangulation).
struct FillContext {
  const Volume& volume;
  const PackOptions& options;
  SphereGrid& grid;
  Packing& out;
  const std::vector<double>* radii = nullptr;  ///< power-law mode: radii largest first
  std::size_t next = 0;                        ///< first radius of `radii` not yet placed
  double expected_solid = 1;                   ///< for progress: solid volume expected at the end
  double placed_solid = 0;
  std::size_t not_placed = 0;      ///< power-law mode: radii for which no void was left
  Random* rng = nullptr;           ///< for the room probes after filling (the seeding's stream)
  std::size_t probed_spheres = 0;  ///< spheres placed where a probe found room the triangulation missed
  /// A tile of a split pack (docs/packer.md, "Tiles"): only centres within this box are placed here (the
  /// volume's own boundary still applies). Unbounded for a pack in one piece.
  Bounds centre_range{{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, {HUGE_VAL, HUGE_VAL, HUGE_VAL}};
  bool in_range(const Vec3& c) const {
    for (int k = 0; k < 3; ++k)
      if (!(c[k] >= centre_range.lo[k] && c[k] <= centre_range.hi[k])) return false;
    return true;
  }
};

/// Places spheres into the voids left between out's spheres until none of radius >= rmin is left
/// (dense mode) or the radii are used up (power-law mode).
void fill_voids(FillContext& ctx);

}  // namespace basalt::packer::detail
