#pragma once
// Table 2 of Weatherley et al. (2010) without running the ranks: the solver's domain decomposition and
// ghost exchange replayed serially over every subdomain of a grid, to count per subdomain the owned
// particles, the ghosts, the bonds crossing subdomain faces and the bytes a ghost update moves per step.
//
// The solver's Decomposition needs an MPI communicator (it builds an MPI Cartesian grid), so the pure
// arithmetic it applies is replicated here in `region_bounds` / `region_coord` (identical expressions,
// so ownership agrees bit for bit) and the phase exchange of Halo::build_ghosts in `partition`.
// tests/bench/partition_study_test.cpp checks both against the real Decomposition + Halo at np 1, 2, 4.
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace basalt::io {
struct Geometry;
}

namespace basalt::bench {

/// Particle centres (structure of arrays) and bonds by index. The bond list may describe one tile that
/// is repeated `bond_tiles` times with an index stride of `bond_stride` (a tiled cube keeps one copy).
struct Cloud {
  std::vector<double> x, y, z;
  double rmax = 0;
  double longest_bond = 0;
  std::array<double, 3> box_min{}, box_max{};  ///< bounding box of the spheres: min(c - r), max(c + r)
  std::vector<std::pair<std::uint32_t, std::uint32_t>> bonds;
  std::uint32_t bond_tiles = 1;
  std::uint32_t bond_stride = 0;
  std::size_t size() const { return x.size(); }
  std::size_t bond_count() const { return bonds.size() * bond_tiles; }
};

/// The solver's ghost width (Simulation::distribute): max(2 rmax if contacts are modelled, longest
/// bond) + skin.
double ghost_width(double rmax, double longest_bond, bool contacts, double skin);

/// Region [lo, hi) of grid coordinate c along an axis cut into `dims` equal slabs of [box_min, box_max);
/// the first and last slabs extend to -inf / +inf (Decomposition's open outer faces).
std::pair<double, double> region_bounds(int c, int dims, double box_min, double box_max);
/// Grid coordinate along an axis of the region owning coordinate v (Decomposition::coord_of).
int region_coord(double v, int dims, double box_min, double box_max);

/// Per subdomain (rank in row-major order of MPI_Cart_create: z fastest).
struct SubdomainStats {
  std::array<int, 3> coords{};
  std::uint64_t owned = 0;
  std::uint64_t ghosts = 0;          ///< ghost copies held (received in the 3 axis phases)
  std::uint64_t sent = 0;            ///< ghost records this subdomain sends per update (with forwarding)
  std::uint64_t crossing_bonds = 0;  ///< bonds with one end owned here and the other owned elsewhere
  int messages = 0;                  ///< sends per ghost update to real (non-null) neighbours
};

struct PartitionResult {
  std::array<int, 3> dims{};
  double width = 0;
  std::vector<SubdomainStats> sub;
  std::uint64_t crossing_bonds = 0;  ///< distinct bonds whose ends are owned by different subdomains
  /// Ghost global indices per subdomain, sorted (filled only when asked for: tests).
  std::vector<std::vector<std::uint32_t>> ghost_index;
};

/// Rank in an MPI Cartesian grid (row-major, last dimension fastest) of grid coordinates c.
int cart_rank(const std::array<int, 3>& c, const std::array<int, 3>& dims);

/// Owns every particle by its centre, then replays Halo::build_ghosts: along x, then y, then z (axes
/// with one slab skipped), every particle held (owned or ghost from an earlier axis) within `width` of
/// a face with a neighbour is sent to that neighbour; what arrives along an axis is not sent again
/// along the same axis. The ghost update (Halo::update_ghosts) sends along the same lists.
PartitionResult partition(const Cloud& cloud, const std::array<int, 3>& dims, double width,
                          bool keep_ghost_index = false);

/// Bytes of one ghost record in Halo::update_ghosts: x, y, z in the solver's Real.
constexpr std::size_t kGhostUpdateBytes = 3 * sizeof(double);
/// Bytes of one ghost record in Halo::build_ghosts (GhostRecord: id, tag, pad, x, y, z, radius).
constexpr std::size_t kGhostBuildBytes = 8 + 4 + 4 + 4 * 8;

/// Reads an LSMGeometry (.geo) or HDF5 geometry through basalt::io into a cloud (bonds by index).
Cloud load_cloud(const std::string& path);
Cloud cloud_from_geometry(const io::Geometry& g);
/// n x n x n copies of `base`, each shifted by `side` along the axes; bonds within copies only.
Cloud tile_cloud(const Cloud& base, int n, double side);

}  // namespace basalt::bench
