#include "basalt/solver/parallel/decomposition.hpp"

#include <fmt/format.h>

#include <cmath>

#include "basalt/solver/core/errors.hpp"

namespace basalt::solver {

namespace {
MPI_Comm make_cart(const Comm& comm, std::array<int, 3>& dims) {
  const int n = comm.size();
  if (dims[0] == 0 && dims[1] == 0 && dims[2] == 0) {
    MPI_Dims_create(n, 3, dims.data());
  } else if (dims[0] < 1 || dims[1] < 1 || dims[2] < 1 || dims[0] * dims[1] * dims[2] != n) {
    throw InputError(fmt::format("--dims {},{},{}: the product must equal the number of ranks ({})", dims[0],
                                 dims[1], dims[2], n));
  }
  std::array<int, 3> periods{0, 0, 0};
  MPI_Comm cart = MPI_COMM_NULL;
  MPI_Cart_create(comm.raw(), 3, dims.data(), periods.data(), 0, &cart);
  return cart;
}
}  // namespace

Decomposition::Decomposition(const Comm& comm, std::array<int, 3> dims, const std::array<double, 3>& box_min,
                             const std::array<double, 3>& box_max)
    : cart_raw_(make_cart(comm, dims)), cart_(cart_raw_), dims_(dims), box_min_(box_min), box_max_(box_max) {
  MPI_Cart_coords(cart_raw_, cart_.rank(), 3, coords_.data());
  for (int d = 0; d < 3; ++d) {
    MPI_Cart_shift(cart_raw_, d, 1, &nb_[d][0], &nb_[d][1]);
    const double w = (box_max_[d] - box_min_[d]) / dims_[d];
    const int c = coords_[d];
    lo_[d] = c == 0 ? -std::numeric_limits<double>::infinity() : box_min_[d] + c * w;
    hi_[d] = c == dims_[d] - 1 ? std::numeric_limits<double>::infinity() : box_min_[d] + (c + 1) * w;
  }
  rank_table_.resize(static_cast<std::size_t>(dims_[0] * dims_[1] * dims_[2]));
  for (int i = 0; i < dims_[0]; ++i)
    for (int j = 0; j < dims_[1]; ++j)
      for (int k = 0; k < dims_[2]; ++k) {
        const int c[3] = {i, j, k};
        MPI_Cart_rank(cart_raw_, c,
                      &rank_table_[static_cast<std::size_t>((i * dims_[1] + j) * dims_[2] + k)]);
      }
}

Decomposition::~Decomposition() {
  if (cart_raw_ != MPI_COMM_NULL) MPI_Comm_free(&cart_raw_);
}

int Decomposition::coord_of(int d, double v) const {
  const double w = (box_max_[d] - box_min_[d]) / dims_[d];
  int c = 0;
  // Same arithmetic as the region bounds, so ownership agrees with owns().
  while (c < dims_[d] - 1 && v >= box_min_[d] + (c + 1) * w) ++c;
  return c;
}

double Decomposition::min_interior_width() const {
  double m = std::numeric_limits<double>::infinity();
  for (int d = 0; d < 3; ++d)
    if (dims_[d] > 2) m = std::min(m, (box_max_[d] - box_min_[d]) / dims_[d]);
  return m;
}

}  // namespace basalt::solver
