#pragma once
// Uniform cell grid over the bounding box of the local particles (owned + ghosts), sized at each
// rebuild from their actual extent: cells at least `cell` wide. Counting sort: particles of cell c are
// order[start[c] .. start[c+1]); cells are numbered x fastest, so a row of cells along x is one range.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace basalt::solver {

class CellGrid {
 public:
  /// Sizes the grid over the extent of particles [0, n) with cells at least `cell` wide and sorts them
  /// into it.
  template <class Real>
  void build(const std::vector<Real>& x, const std::vector<Real>& y, const std::vector<Real>& z,
             std::size_t n, double cell) {
    size_to(x, y, z, n, cell);
    fill(x, y, z, 0, n);
  }

  /// Sizes the grid over the extent of particles [0, n); fill() then sorts particles into it.
  template <class Real>
  void size_to(const std::vector<Real>& x, const std::vector<Real>& y, const std::vector<Real>& z,
               std::size_t n, double cell) {
    std::array<double, 3> lo{0, 0, 0}, hi{0, 0, 0};
    if (n > 0) {
      lo = hi = {double(x[0]), double(y[0]), double(z[0])};
      for (std::size_t i = 1; i < n; ++i) {
        lo[0] = std::min(lo[0], double(x[i]));
        hi[0] = std::max(hi[0], double(x[i]));
        lo[1] = std::min(lo[1], double(y[i]));
        hi[1] = std::max(hi[1], double(y[i]));
        lo[2] = std::min(lo[2], double(z[i]));
        hi[2] = std::max(hi[2], double(z[i]));
      }
    }
    // Never more cells than ~2 per particle: a particle far from the rest widens the cells instead.
    double size = cell;
    for (;;) {
      std::uint64_t total = 1;
      for (int d = 0; d < 3; ++d) {
        n_[d] = std::max<std::int64_t>(1, static_cast<std::int64_t>((hi[d] - lo[d]) / size));
        total *= static_cast<std::uint64_t>(n_[d]);
      }
      if (total <= 2 * n + 64) break;
      size *= 1.26;
    }
    for (int d = 0; d < 3; ++d) {
      lo_[d] = lo[d];
      inv_[d] = n_[d] / std::max(hi[d] - lo[d], 1e-300);
    }
  }

  /// The same cells as `other` (empty until fill()).
  void size_like(const CellGrid& other) {
    lo_ = other.lo_;
    inv_ = other.inv_;
    n_ = other.n_;
  }

  /// Counting sort of particles [first, last) into the cells (particles outside the extent go to the
  /// nearest cell): those of cell c are order[start[c] .. start[c+1]), in increasing index.
  template <class Real>
  void fill(const std::vector<Real>& x, const std::vector<Real>& y, const std::vector<Real>& z,
            std::size_t first, std::size_t last) {
    const std::size_t ncell = static_cast<std::size_t>(n_[0] * n_[1] * n_[2]), n = last - first;
    first_ = first;
    start_.assign(ncell + 1, 0);
    cell_of_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      cell_of_[i] = static_cast<std::uint32_t>(index(x[first + i], y[first + i], z[first + i]));
      ++start_[cell_of_[i] + 1];
    }
    for (std::size_t c = 0; c < ncell; ++c) start_[c + 1] += start_[c];
    order_.resize(n);
    std::vector<std::uint32_t> at(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order_[at[cell_of_[i]]++] = static_cast<std::uint32_t>(first + i);
  }

  std::int64_t coord(int d, double v) const {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>((v - lo_[d]) * inv_[d]), 0, n_[d] - 1);
  }
  std::int64_t index(double px, double py, double pz) const {
    return (coord(2, pz) * n_[1] + coord(1, py)) * n_[0] + coord(0, px);
  }
  const std::array<std::int64_t, 3>& dims() const { return n_; }
  /// Cell of particle i (one of those filled).
  std::uint32_t cell_of(std::size_t i) const { return cell_of_[i - first_]; }
  const std::vector<std::uint32_t>& start() const { return start_; }
  const std::vector<std::uint32_t>& order() const { return order_; }
  std::size_t memory_bytes() const {
    return (start_.capacity() + cell_of_.capacity() + order_.capacity()) * sizeof(std::uint32_t);
  }
  void release() {
    std::vector<std::uint32_t>().swap(start_);
    std::vector<std::uint32_t>().swap(cell_of_);
    std::vector<std::uint32_t>().swap(order_);
  }

 private:
  std::array<double, 3> lo_{}, inv_{};
  std::array<std::int64_t, 3> n_{1, 1, 1};
  std::size_t first_ = 0;
  std::vector<std::uint32_t> start_, cell_of_, order_;
};

}  // namespace basalt::solver
