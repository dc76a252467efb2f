#pragma once
// 3-D Cartesian decomposition of space over the compute ranks. The cut planes along each axis split
// the geometry's bounding box evenly at first; load balancing (parallel/balance.hpp) may move them
// (per axis, dims - 1 increasing cuts: a weighted grid with the same neighbours). Ranks on the outer
// faces of the grid own half-infinite regions, so the domain follows particles that leave the
// initial box (open boundaries).
#include <mpi.h>

#include <array>
#include <limits>
#include <vector>

#include "basalt/solver/parallel/communicator.hpp"

namespace basalt::solver {

/// The rank grid for n ranks on this box when the user names none: MPI_Dims_create's, unless another
/// grid cuts the box with at least 10 % less plane area (LAMMPS's `processors * * *` takes the least
/// area; MPI_Dims_create ignores the box, and splits a 10 x 10 x 20 specimen across its length on 2
/// ranks: twice the ghosts and the bonds evaluated on both sides). Near-cubic boxes keep MPI's grid.
std::array<int, 3> default_dims(int n, const std::array<double, 3>& box_min,
                                const std::array<double, 3>& box_max);

class Decomposition {
 public:
  /// dims: {0,0,0} lets default_dims choose; else the product must equal the number of ranks.
  /// Throws InputError when dims do not fit.
  Decomposition(const Comm& comm, std::array<int, 3> dims, const std::array<double, 3>& box_min,
                const std::array<double, 3>& box_max);
  ~Decomposition();
  Decomposition(const Decomposition&) = delete;
  Decomposition& operator=(const Decomposition&) = delete;

  const Comm& comm() const { return cart_; }
  const std::array<int, 3>& dims() const { return dims_; }
  const std::array<int, 3>& coords() const { return coords_; }
  /// Neighbouring rank along axis d on side 0 (low) or 1 (high); MPI_PROC_NULL on an open face.
  int neighbor(int d, int side) const { return nb_[d][side]; }
  /// The box the cut planes split (restart rebuilds the same decomposition from it).
  const std::array<double, 3>& box_min() const { return box_min_; }
  const std::array<double, 3>& box_max() const { return box_max_; }
  /// The dims[d] - 1 interior cut planes along axis d, increasing: region c spans [cut c-1, cut c).
  const std::vector<double>& cuts(int d) const { return cuts_[d]; }
  /// Moves the cut planes (every rank must pass the same ones): owners change, so particles must
  /// migrate afterwards. Throws InputError when an axis has not dims[d] - 1 increasing finite cuts.
  void set_cuts(const std::array<std::vector<double>, 3>& cuts);
  double lo(int d) const { return lo_[d]; }
  double hi(int d) const { return hi_[d]; }
  /// Grid coordinate along d of the rank owning coordinate v.
  int coord_of(int d, double v) const;
  /// The rank owning a point (the one whose owns() is true for it).
  int rank_of(double x, double y, double z) const {
    return rank_table_[static_cast<std::size_t>((coord_of(0, x) * dims_[1] + coord_of(1, y)) * dims_[2] +
                                                coord_of(2, z))];
  }
  bool owns(double x, double y, double z) const {
    return x >= lo_[0] && x < hi_[0] && y >= lo_[1] && y < hi_[1] && z >= lo_[2] && z < hi_[2];
  }
  /// Smallest width of an interior (finite) region, infinity when there is none.
  double min_interior_width() const;

 private:
  void set_bounds();  ///< lo_, hi_ of this rank's region from cuts_

  MPI_Comm cart_raw_ = MPI_COMM_NULL;
  Comm cart_;
  std::array<int, 3> dims_{1, 1, 1};
  std::array<int, 3> coords_{0, 0, 0};
  std::array<std::array<int, 2>, 3> nb_{};
  std::array<double, 3> box_min_{}, box_max_{};
  std::array<double, 3> lo_{}, hi_{};
  std::array<std::vector<double>, 3> cuts_;
  std::vector<int> rank_table_;  ///< rank of grid coordinates (x * dims[1] + y) * dims[2] + z
};

}  // namespace basalt::solver
