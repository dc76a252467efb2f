#pragma once
// From placed spheres to a geometry file: bonds, region tags, statistics.
#include <cstdint>
#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/packer/pack.hpp"
#include "basalt/packer/volume.hpp"

namespace basalt::packer {

/// "Tag particles near a face": every particle whose distance to the face (its surface's, i.e. the
/// centre's distance minus the radius) is <= thickness gets `tag`. Face: a piece name of the volume
/// ("xmin" ... "zmax" for a box, "side"/"bottom"/"top" for a cylinder) or "surface" for every piece.
struct TagLayer {
  std::string face;
  double thickness = 0;
  std::int32_t tag = 0;
};
/// Parses "FACE:THICKNESS:TAG"; throws PackError naming the text when malformed.
TagLayer parse_tag_layer(const std::string& text);
/// Tags per particle (0 by default; later layers win). Throws PackError for a face the volume lacks.
std::vector<std::int32_t> region_tags(const Volume& volume, const std::vector<Vec3>& centre,
                                      const std::vector<double>& radius, const std::vector<TagLayer>& layers);

/// Log-binned radius histogram and the fitted exponent alpha (docs/packer.md): bins equally spaced in
/// ln r over [rmin, rmax]; alpha = -slope of the least-squares line through (ln r_centre, ln count) over
/// non-empty bins, each weighted by its count. For N(>r) ~ r^-alpha the counts per bin go as r^-alpha.
struct RadiusHistogram {
  std::vector<double> edges;   ///< bins + 1 values
  std::vector<double> counts;  ///< bins values
  double exponent = 0;         ///< NaN when fewer than two bins are non-empty
};
RadiusHistogram radius_histogram(const std::vector<double>& radius, double rmin, double rmax, int bins);

struct AssemblyOptions {
  bool bonds = true;
  double bond_tolerance = 1e-5;
  std::int32_t bond_tag = 0;
  std::vector<TagLayer> tags;
  int histogram_bins = 16;
  int threads = 2;
};

struct AssemblyStats {
  std::size_t particles = 0;
  double solid_fraction = 0;
  RadiusHistogram histogram;
  std::size_t bonds = 0;
  double bonds_per_particle = 0;
  double mean_coordination = 0;         ///< touching neighbours per particle (gap <= bond tolerance)
  double largest_overlap = 0;           ///< between two spheres
  double largest_boundary_overlap = 0;  ///< of a sphere beyond the boundary
  double min_radius = 0, max_radius = 0;
};

/// Builds the geometry (ids 0..N-1 in placement order, tags, bonds) and its statistics; stores the
/// statistics in geometry.statistics and describes them in the returned struct.
basalt::io::Geometry assemble(const Volume& volume, const Packing& packing, const PackOptions& pack_options,
                              const AssemblyOptions& options, AssemblyStats& stats);

}  // namespace basalt::packer
