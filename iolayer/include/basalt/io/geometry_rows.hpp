#pragma once
// Reading a basalt-geometry HDF5 file in parts: its header (row counts, units, box, provenance), then
// any range of particle rows and of bond rows, each read as an HDF5 hyperslab of the file's datasets.
// basalt-run's compute ranks each read one slice of the rows this way and route them to the ranks that
// own them (solver/src/geometry_loader.cpp), so no process holds the whole geometry.
#include <cstddef>
#include <filesystem>
#include <memory>

#include "basalt/io/geometry.hpp"

namespace basalt::io {

/// A geometry file's description without its rows.
struct GeometryHeader {
  std::size_t particles = 0;
  std::size_t bonds = 0;
  bool has_mass = false;
  Vec3 box_min{0, 0, 0};
  Vec3 box_max{0, 0, 0};
  std::array<bool, 3> periodic{false, false, false};
  Units units;
  std::map<std::string, std::string> attributes;
};

/// One open geometry file (.h5/.hdf5, schema basalt-geometry). Errors are FormatErrors naming the file
/// and the dataset, as read_h5's are.
class GeometryFile {
 public:
  /// Opens the file and checks its schema, attributes and datasets' types and shapes (reads no rows).
  explicit GeometryFile(const std::filesystem::path& file);
  ~GeometryFile();
  GeometryFile(const GeometryFile&) = delete;
  GeometryFile& operator=(const GeometryFile&) = delete;

  const std::filesystem::path& path() const;
  const GeometryHeader& header() const { return header_; }

  /// Particle rows [begin, end) into `out`'s id, position, radius, tag and (when the file has them)
  /// mass, replacing what they held. Checked as read_h5 checks them: positions finite, radius (and mass)
  /// finite and > 0, ids strictly ascending within these rows (across slices: the caller's check).
  void read_particles(std::size_t begin, std::size_t end, Geometry& out) const;
  /// Bond rows [begin, end), each checked a != b and a < b. That both ids exist and no pair is bonded
  /// twice is the caller's check (it needs the rows of other slices).
  std::vector<Bond> read_bonds(std::size_t begin, std::size_t end) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  GeometryHeader header_;
};

/// The rows [begin, end) of slice `part` of `parts` equal slices of n rows (the first n % parts slices
/// one row longer).
std::pair<std::size_t, std::size_t> slice_rows(std::size_t n, int part, int parts);

}  // namespace basalt::io
