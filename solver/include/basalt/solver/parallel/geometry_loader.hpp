#pragma once
// Start-up without any rank holding the whole geometry (issue 14). Each compute rank reads one equal slice
// of the file's particle rows and of its bond rows (HDF5 hyperslabs through io::GeometryFile), then the
// ranks route what they read to where it belongs, by three kinds of personalised exchange:
//  1. particles to the rank owning their position;
//  2. bonds to the owners of both ends (the slice holding an id - ids are sorted, so slices are ranges of
//     ids - tells each bond's reader the owners of its ends);
//  3. the far ends of bonds whose other end a rank owns (ghost ends), asked of the slice holding them.
// A rank holds its slice (N/P particles, M/P bonds) plus its own part; nothing it holds grows with the
// whole file at a fixed number of particles per rank. What arrives is kept in file order, so each rank
// ends with exactly the particles and bonds, in the same order, that it used to filter out of the whole
// geometry: the run is bit for bit the same as when every rank read the whole file.
#include <array>
#include <cstdint>

#include "basalt/io/geometry.hpp"
#include "basalt/io/geometry_rows.hpp"
#include "basalt/solver/parallel/communicator.hpp"
#include "basalt/solver/parallel/decomposition.hpp"
#include "basalt/solver/parallel/id_slices.hpp"

namespace basalt::solver {

/// The geometry-wide numbers the decomposition and the id map need.
struct GeometryExtent {
  std::array<double, 3> lo{}, hi{};  ///< bounding box of the spheres (centre -+ radius)
  double rmax = 0;
  std::int64_t n = 0, first_id = 0, last_id = 0;
};
/// The extent of a whole geometry held by one rank.
GeometryExtent extent_of(const io::Geometry& g);

/// What this rank read and received at start-up.
struct LoadStats {
  std::size_t particle_rows = 0;  ///< particle rows read from the file (its slice)
  std::size_t bond_rows = 0;      ///< bond rows read from the file
  std::size_t owned = 0;          ///< particles received as owned
  std::size_t ghost_ends = 0;     ///< far ends of bonds received
  std::size_t bonds = 0;          ///< bonds received (with an owned end)
};

class GeometryLoader {
 public:
  /// Collective: reads this rank's slice of the particle rows and of the bond rows (slice().bonds: what
  /// the load checks summarise, bond tags included) and reduces the extent. A bad file is an InputError
  /// (naming the file and dataset) on every rank alike.
  GeometryLoader(const io::GeometryFile& file, const Comm& comm);
  const io::Geometry& slice() const { return slice_; }
  const GeometryExtent& extent() const { return extent_; }
  /// Subtracts o from the slice's positions and the extent's box (run.precision = "mixed": the run's
  /// frame, scene/frame_origin.hpp); before local_part().
  void to_frame(const std::array<double, 3>& o);
  /// Collective: this rank's part under `dec`: the particles it owns, the far ends of bonds with an
  /// owned end, and those bonds; particles by ascending id, bonds in file order, mass only if the file has
  /// it. Checks what slices cannot alone: ids ascending across slices, bond ends exist, no pair bonded
  /// twice. Releases the slice.
  io::Geometry local_part(const Decomposition& dec);
  const LoadStats& stats() const { return stats_; }

 private:
  const io::GeometryFile& file_;
  const Comm& comm_;
  io::Geometry slice_;
  GeometryExtent extent_;
  LoadStats stats_;
  IdSlices slices_;  ///< which rank's slice holds an id
};

}  // namespace basalt::solver
