#include "basalt/solver/parallel/decomposition.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "basalt/solver/core/errors.hpp"

namespace basalt::solver {

std::array<int, 3> default_dims(int n, const std::array<double, 3>& box_min,
                                const std::array<double, 3>& box_max) {
  std::array<int, 3> dims{0, 0, 0};
  MPI_Dims_create(n, 3, dims.data());
  std::array<double, 3> len{};
  for (int d = 0; d < 3; ++d) len[d] = std::max(box_max[d] - box_min[d], 0.0);
  if (!std::isfinite(len[0] + len[1] + len[2])) return dims;
  // The area of the interior cut planes: dims[d] - 1 planes across the box's other two extents.
  const auto area = [&](const std::array<int, 3>& g) {
    return (g[0] - 1) * len[1] * len[2] + (g[1] - 1) * len[0] * len[2] + (g[2] - 1) * len[0] * len[1];
  };
  std::array<int, 3> best = dims;
  for (int a = 1; a <= n; ++a)
    for (int b = 1; a * b <= n; ++b)
      if (n % (a * b) == 0) {
        const std::array<int, 3> g{a, b, n / (a * b)};
        if (area(g) < area(best)) best = g;
      }
  return area(best) < 0.9 * area(dims) ? best : dims;
}

namespace {
MPI_Comm make_cart(const Comm& comm, std::array<int, 3>& dims, const std::array<double, 3>& box_min,
                   const std::array<double, 3>& box_max) {
  const int n = comm.size();
  if (dims[0] == 0 && dims[1] == 0 && dims[2] == 0) {
    dims = default_dims(n, box_min, box_max);
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
    : cart_raw_(make_cart(comm, dims, box_min, box_max)),
      cart_(cart_raw_),
      dims_(dims),
      box_min_(box_min),
      box_max_(box_max) {
  MPI_Cart_coords(cart_raw_, cart_.rank(), 3, coords_.data());
  for (int d = 0; d < 3; ++d) {
    MPI_Cart_shift(cart_raw_, d, 1, &nb_[d][0], &nb_[d][1]);
    // The even split: the same arithmetic as before cuts could move (box_min + c w), bit for bit.
    const double w = (box_max_[d] - box_min_[d]) / dims_[d];
    for (int c = 1; c < dims_[d]; ++c) cuts_[d].push_back(box_min_[d] + c * w);
  }
  set_bounds();
  rank_table_.resize(static_cast<std::size_t>(dims_[0] * dims_[1] * dims_[2]));
  for (int i = 0; i < dims_[0]; ++i)
    for (int j = 0; j < dims_[1]; ++j)
      for (int k = 0; k < dims_[2]; ++k) {
        const int c[3] = {i, j, k};
        MPI_Cart_rank(cart_raw_, c,
                      &rank_table_[static_cast<std::size_t>((i * dims_[1] + j) * dims_[2] + k)]);
      }
}

void Decomposition::set_bounds() {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (int d = 0; d < 3; ++d) {
    const auto c = static_cast<std::size_t>(coords_[d]);
    lo_[d] = c == 0 ? -kInf : cuts_[d][c - 1];
    hi_[d] = coords_[d] == dims_[d] - 1 ? kInf : cuts_[d][c];
  }
}

void Decomposition::set_cuts(const std::array<std::vector<double>, 3>& cuts) {
  for (int d = 0; d < 3; ++d) {
    const auto& v = cuts[static_cast<std::size_t>(d)];
    if (v.size() != static_cast<std::size_t>(dims_[d] - 1))
      throw InputError(fmt::format("decomposition: {} cut(s) along {} for {} rank(s) along that axis",
                                   v.size(), "xyz"[d], dims_[d]));
    for (std::size_t k = 0; k < v.size(); ++k)
      if (!std::isfinite(v[k]) || (k > 0 && !(v[k] > v[k - 1])))
        throw InputError(
            fmt::format("decomposition: the cuts along {} are not finite and increasing", "xyz"[d]));
  }
  cuts_ = cuts;
  set_bounds();
}

Decomposition::~Decomposition() {
  if (cart_raw_ != MPI_COMM_NULL) MPI_Comm_free(&cart_raw_);
}

int Decomposition::coord_of(int d, double v) const {
  // The same cut values as the region bounds, so ownership agrees with owns().
  const auto& cuts = cuts_[d];
  return static_cast<int>(std::upper_bound(cuts.begin(), cuts.end(), v) - cuts.begin());
}

double Decomposition::min_interior_width() const {
  double m = std::numeric_limits<double>::infinity();
  for (int d = 0; d < 3; ++d)
    for (std::size_t c = 1; c < cuts_[d].size(); ++c) m = std::min(m, cuts_[d][c] - cuts_[d][c - 1]);
  return m;
}

}  // namespace basalt::solver
