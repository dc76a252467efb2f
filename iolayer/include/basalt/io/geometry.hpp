#pragma once
// A sphere assembly as it travels between basalt-pack, basalt-run and other codes:
// particles (sorted by global id), bonds, bounding box, units and provenance.
// Stored as HDF5 (docs/formats.md, schema "basalt-geometry" version 1) or as
// ESyS-Particle's text format "LSMGeometry 1.2" (.geo).
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace basalt::io {

using Vec3 = std::array<double, 3>;

/// Error in an input or output file. what() names the file and the line or dataset.
class FormatError : public std::runtime_error {
 public:
  FormatError(const std::filesystem::path& file, const std::string& where, const std::string& what);
  const std::filesystem::path& file() const { return file_; }
  const std::string& where() const { return where_; }

 private:
  std::filesystem::path file_;
  std::string where_;
};

struct Bond {
  std::int64_t a = 0;  ///< global id of one end
  std::int64_t b = 0;  ///< global id of the other end
  std::int32_t tag = 0;
  friend bool operator==(const Bond&, const Bond&) = default;
};

struct Units {
  std::string length = "mm";
  std::string time = "ms";
  std::string force = "N";
  std::string mass = "";  ///< derived from the three above when empty
  friend bool operator==(const Units&, const Units&) = default;
};

struct Geometry {
  // Particles, one entry each, sorted by id after sort_by_id().
  std::vector<std::int64_t> id;
  std::vector<Vec3> position;
  std::vector<double> radius;
  std::vector<std::int32_t> tag;
  std::vector<double> mass;  ///< empty when the file gives none (the solver derives it from density)

  std::vector<Bond> bonds;

  Vec3 box_min{0, 0, 0};
  Vec3 box_max{0, 0, 0};
  std::array<bool, 3> periodic{false, false, false};
  Units units;

  /// Free-form provenance: creator, version, command line, seed, source file ...
  std::map<std::string, std::string> attributes;
  /// Named numeric series stored with the geometry, e.g. the packer's statistics
  /// ("solid_fraction" -> {0.68}, "radius_histogram_counts" -> {...}).
  std::map<std::string, std::vector<double>> statistics;

  std::size_t size() const { return id.size(); }
  bool has_mass() const { return !mass.empty(); }

  /// Append one particle (mass only if the geometry carries masses).
  void add_particle(std::int64_t pid, const Vec3& pos, double r, std::int32_t ptag = 0);
  void add_bond(std::int64_t a, std::int64_t b, std::int32_t btag = 0) { bonds.push_back({a, b, btag}); }

  /// Sort particles by id (bonds keep their order; each bond is stored with a < b).
  void sort_by_id();

  /// Checks the invariants every reader and writer relies on; throws FormatError naming `source`
  /// and the first offending particle or bond: array lengths agree, radii finite and > 0,
  /// positions finite, ids unique, bonds join two existing, distinct ids, no pair bonded twice,
  /// masses > 0.
  void validate(const std::filesystem::path& source) const;

  /// Two bonds joining the same pair (in either order), as their indices (first < second), if any: a
  /// duplicate would act as two springs. O(B log B) time, 16 bytes per bond while it runs.
  std::optional<std::pair<std::size_t, std::size_t>> duplicate_bond() const;

  /// Index of a particle by id, or -1. O(log n): requires sort_by_id() to have been called.
  std::int64_t index_of(std::int64_t pid) const;
};

/// The geometry formats, told apart by the file's extension (any case): .h5/.hdf5 (Basalt's HDF5 schema,
/// docs/formats.md) and .geo (ESyS-Particle's text geometry, as GenGeo writes it).
enum class GeometryFormat { h5, geo };
/// The format of `file` by its extension; any other extension is a FormatError naming the ones read.
GeometryFormat geometry_format(const std::filesystem::path& file);

/// Reads .h5/.hdf5 (Basalt schema) or .geo (ESyS-Particle) by extension; validates; sorts by id.
Geometry read_geometry(const std::filesystem::path& file);
/// Writes by extension (.h5/.hdf5 or .geo). Writes to a temporary name and renames, so a failed
/// write never leaves a partial file under the final name. Throws FormatError on failure.
void write_geometry(const Geometry& g, const std::filesystem::path& file);

Geometry read_geo(const std::filesystem::path& file);
void write_geo(const Geometry& g, const std::filesystem::path& file);
Geometry read_h5(const std::filesystem::path& file);
void write_h5(const Geometry& g, const std::filesystem::path& file);

}  // namespace basalt::io
