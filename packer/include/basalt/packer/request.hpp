#pragma once
// A pack as basalt-pack's command line asks for it, from the checks before any work to the bonded geometry.
// basalt-pack and the Python package (basalt.pack, python/src/pack.cpp) both go through here, so that the
// same request gives the same spheres and bonds and the same error messages (each names the command-line
// option:
// "--seed '-1': a seed cannot be negative; ...").
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/packer/assembly.hpp"
#include "basalt/packer/pack.hpp"
#include "basalt/packer/volume.hpp"

namespace basalt::packer {

enum class Shape { box, cylinder, sphere, mesh };

/// The command line's options, as given (vectors and the seed as text, parsed by prepare()).
struct Request {
  Shape shape = Shape::box;
  std::string size;              ///< box: edge lengths "X,Y,Z" (--size)
  std::string origin = "0,0,0";  ///< box: lowest corner; cylinder: centre of the base (--origin)
  std::string centre = "0,0,0";  ///< sphere (--centre)
  double radius = 0;             ///< cylinder, sphere (--radius)
  double height = 0;             ///< cylinder (--height)
  std::filesystem::path mesh_file;
  std::string seed = "1";  ///< --seed: a whole number in [0, 2^64)
  /// rmin, rmax, exponent, target fraction, fill, overlap tolerance, seed fraction. Its seed and threads are
  /// set by prepare() from `seed` and `assembly.threads`.
  PackOptions pack;
  /// Bond tolerance and tag, histogram bins, threads. Its bonds and tags are set by prepare() from
  /// `no_bonds` and `tag_layers`.
  AssemblyOptions assembly;
  std::vector<std::string> tag_layers;  ///< "FACE:THICKNESS:TAG" each (--tag-layer)
  bool no_bonds = false;
  bool lattice = false;
  double max_spheres = 1e7;
  bool allow_large = false;
  bool allow_low_fraction = false;
  /// When not empty, checked before any work (extension, folder exists and is writable); the caller writes.
  std::filesystem::path output;
};

/// A request that passed every check: final options and the volume.
struct PreparedPack {
  PackOptions pack;
  AssemblyOptions assembly;
  std::unique_ptr<Volume> volume;
  bool lattice = false;
  bool allow_low_fraction = false;
};

/// What a pack made. The geometry has ids, tags, bonds and statistics, and no provenance: the caller adds
/// its creator and command line.
struct PackResult {
  basalt::io::Geometry geometry;
  AssemblyStats stats;
  std::size_t requested = 0;   ///< power-law mode: radii drawn
  std::size_t not_placed = 0;  ///< power-law mode: drawn radii for which no void was left
  /// A solid fraction below the mode's, and why (empty text: as expected; always empty for a lattice).
  /// far_below: written only because allow_low_fraction asks, the caller warns.
  LowFractionReport low;
};

/// "X,Y,Z" for the option named `option`; throws PackError naming both.
Vec3 parse_vec3(const std::string& text, const char* option);
/// --seed: a whole number in [0, 2^64) (CLI11 would store -1 as 2^64 - 1 without a word).
std::uint64_t parse_seed(const std::string& text);
/// Fails early, before any packing, when the output cannot be written.
void check_output(const std::filesystem::path& out);
/// Refuses, before any work, a pack whose expected sphere count is beyond `limit` unless `allowed` (memory
/// grows about 1 KiB per sphere: --size 1e6,1e6,1e6 ran until std::bad_alloc).
void check_expected_count(const Volume& volume, const PackOptions& options, double limit, bool allowed);

/// Every check basalt-pack makes before it packs, in its order, and the volume; throws PackError.
PreparedPack prepare(const Request& request);

/// Packs and bonds (`packed`, when given, is called between the two, e.g. for a progress line). Throws
/// PackError when the solid fraction is far below the mode's, unless allow_low_fraction or a lattice.
PackResult run(PreparedPack& prepared, const std::function<void()>& packed = {});

}  // namespace basalt::packer
