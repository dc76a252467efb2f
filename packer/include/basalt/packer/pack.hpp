#pragma once
// Sphere packing: radii in [rmin, rmax], no overlap beyond a tolerance, every sphere inside the volume.
// Two modes:
//  * dense (no exponent): GenGeo's aim, fill as densely as possible; the size distribution emerges.
//  * power law (exponent alpha): radii follow the truncated power law N(>r) ~ r^-alpha (equivalently, the
//    number of spheres per logarithmic radius interval ~ r^-alpha), placed largest first until the
//    target solid fraction's worth of spheres is placed; with fill_after, the voids left are then filled
//    as in the dense mode (GenGeo-like assemblies: e.g. exponent 2.2 gives GenGeo's ~9,000 spheres per
//    15 mm cube for radii 0.2-1.0).
// Algorithm (docs/packer.md): random sequential seeding, then void filling on CGAL's regular (weighted
// Delaunay) triangulation of the spheres and their mirror images across the boundary: each cell's void
// gets the largest sphere tangent to its four spheres/planes, biggest voids first.
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "basalt/packer/vec3.hpp"
#include "basalt/packer/volume.hpp"

namespace basalt::packer {

struct PackOptions {
  double rmin = 0.2;
  double rmax = 1.0;
  std::uint64_t seed = 1;
  /// Power-law exponent alpha of N(>r) ~ r^-alpha; empty for the dense mode.
  std::optional<double> exponent;
  /// Power-law mode: solid fraction whose worth of radii is drawn (placed largest first).
  double target_fraction = 0.55;
  /// Power-law mode: afterwards fill the voids left as densely as possible (like the dense mode).
  bool fill_after = false;
  /// Largest allowed overlap between two spheres, and between a sphere and the boundary.
  double overlap_tolerance = 1e-6;
  /// Solid fraction reached by random seeding before void filling starts.
  double seed_fraction = 0.2;
  /// Called now and then with an estimate of the work done, in [0, 1].
  std::function<void(double)> progress;
};

struct Packing {
  std::vector<Vec3> centre;
  std::vector<double> radius;
  std::size_t seeds = 0;       ///< spheres placed by random seeding
  std::size_t requested = 0;   ///< power-law mode: radii drawn
  std::size_t not_placed = 0;  ///< power-law mode: drawn radii for which no void was left
  std::size_t size() const { return radius.size(); }
};

/// Throws PackError on impossible options (rmin <= 0, rmin > rmax, non-finite values ...).
void check_options(const PackOptions& options);

/// Packs the volume. Deterministic: the same volume and options give the same spheres in the same order.
/// Throws PackError when not even one sphere of radius rmin fits.
Packing pack(const Volume& volume, const PackOptions& options);

/// The radii the power-law mode draws for a volume, largest first (exposed for tests).
std::vector<double> power_law_radii(double rmin, double rmax, double alpha, double solid_volume,
                                    std::uint64_t seed);

}  // namespace basalt::packer
