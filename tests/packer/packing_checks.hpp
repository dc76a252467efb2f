#pragma once
// Brute-force oracles for packing tests (O(n^2), independent of the packer's grids).
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

}  // namespace basalt::packer::test
