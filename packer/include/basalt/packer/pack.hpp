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
#include <string>
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
  /// Threads packing tiles of a split pack at the same time; the result does not depend on it.
  int threads = 1;
  /// A box at least two tiles wide is split into tiles of about this width across its two longest axes
  /// (docs/packer.md, "Tiles and threads"); 0: 10 rmax; < 0: never split. At least 4 rmax.
  double tile_width = 0;
  /// Called now and then with an estimate of the work done, in [0, 1] (from any thread, one at a time).
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

/// Largest power-law exponent accepted: beyond it the radii are all but equal to rmin (docs/packer.md).
inline constexpr double kMaxExponent = 20;
/// The dense mode's size distribution, for estimates only: counts per log-radius bin ~ r^-1.5 (1.42 is
/// measured on the 15 mm cube with radii 0.2-1.0; wider radius ranges fill more small voids).
inline constexpr double kDenseCountExponent = 1.5;
/// Memory the packer needs per sphere at its peak, for estimates (measured 0.83-0.93 KiB, docs/packer.md).
inline constexpr double kBytesPerSphere = 1024;

/// A loose granular assembly for flow scenes: a simple cubic lattice of spacing 2 rmax filling the
/// volume (cells whose sphere of radius rmax lies inside), each sphere with a radius uniform in
/// [rmin, rmax] and its centre moved by up to rmax - r along each axis, so no two overlap and none
/// leaves the volume. Deterministic for a seed. Solid fraction about pi/6 <r^3>/rmax^3.
Packing lattice_packing(const Volume& volume, const PackOptions& options);

/// Throws PackError on impossible options (rmin <= 0, rmin > rmax, non-finite values ...).
void check_options(const PackOptions& options);

/// Packs the volume. Deterministic: the same volume and options give the same spheres in the same order.
/// Throws PackError when not even one sphere of radius rmin fits.
Packing pack(const Volume& volume, const PackOptions& options);

/// About how many spheres a pack of a volume of this measure makes: the power law's count at the target
/// fraction, or for the dense mode a power law of exponent kDenseCountExponent at solid fraction 0.72.
/// Within a factor of two of the real count for ordinary radius ranges; may be inf for absurd requests.
double expected_sphere_count(double measure, const PackOptions& options);

/// A solid fraction far below the mode's, and why. The dense mode (and --fill) aims at 0.70 (a 15 mm cube
/// with radii 0.2-1.0); the power-law mode at its target fraction. Below half of it is "far below"; below
/// 0.85 of it a note says why (a volume few rmax across, a narrow radius range, radii left unplaced).
struct LowFractionReport {
  bool far_below = false;
  std::string text;  ///< empty when the fraction is as expected
};
LowFractionReport low_fraction_report(const Volume& volume, const PackOptions& options,
                                      const Packing& packing, double solid_fraction);

/// The radii the power-law mode draws for a volume, largest first (exposed for tests).
std::vector<double> power_law_radii(double rmin, double rmax, double alpha, double solid_volume,
                                    std::uint64_t seed);

}  // namespace basalt::packer
