#pragma once
// Brute-force oracles for packing tests (O(n^2), independent of the packer's grids).
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "basalt/packer/pack.hpp"
#include "basalt/packer/volume.hpp"

namespace basalt::packer::test {

/// Largest overlap ri + rj - |ci - cj| over all pairs (<= 0 when none overlap).
double worst_overlap(const Packing& p);
/// Largest r - signed_distance(c): how far a sphere pokes out of the volume (<= 0 when inside).
double worst_protrusion(const Volume& v, const Packing& p);
/// Every pair (i < j) with gap <= tol.
std::set<std::pair<std::int64_t, std::int64_t>> pairs_within(const Packing& p, double tol);
double solid_fraction(const Volume& v, const Packing& p);
/// Writes text to a file (for meshes made by tests).
void write_text(const std::filesystem::path& file, const std::string& text);
/// A closed cube mesh [0, s]^3 in OFF, outward-oriented; `drop` triangles removed from the end.
std::string cube_off(double s, int drop = 0);

/// Pack options with these radii and seed, the rest default.
inline PackOptions options(double rmin, double rmax, std::uint64_t seed) {
  PackOptions o;
  o.rmin = rmin;
  o.rmax = rmax;
  o.seed = seed;
  return o;
}

/// The invariants every packing must satisfy, checked by brute force: not empty, no overlap and no
/// sphere out of the volume beyond the tolerance, radii within [rmin, rmax].
inline void expect_valid(const Volume& v, const Packing& p, const PackOptions& o) {
  ASSERT_GT(p.size(), 0u);
  EXPECT_LE(worst_overlap(p), o.overlap_tolerance) << v.description();
  EXPECT_LE(worst_protrusion(v, p), o.overlap_tolerance) << v.description();
  for (double r : p.radius) {
    EXPECT_GE(r, o.rmin * (1 - 1e-12));
    EXPECT_LE(r, o.rmax * (1 + 1e-12));
  }
}

}  // namespace basalt::packer::test
