#pragma once
// Verlet pair lists with a skin, built over a cell grid at each rebuild. Half lists: a pair of owned
// particles appears once (i < j, Newton's third law applies); a pair of an owned particle and a ghost
// appears in the ghost list of the owned one (the owning rank of the ghost lists it too; each rank
// applies the force to its own particle only). Bonded pairs are excluded (they interact by their bond).
#include <algorithm>
#include <cstdint>
#include <vector>

#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/neighbor/cell_grid.hpp"

namespace basalt::solver {

/// Compressed rows over owned particles: neighbours of i are neigh[offset[i] .. offset[i+1]).
struct PairList {
  std::vector<std::uint32_t> offset;
  std::vector<std::int32_t> neigh;
  std::size_t pairs() const { return neigh.size(); }
  std::size_t memory_bytes() const {
    return offset.capacity() * sizeof(std::uint32_t) + neigh.capacity() * sizeof(std::int32_t);
  }
};

/// Which pairs are bonded, read from the bond list itself (no copy): bonds ordered by owned end, bucket
/// i holding the bonds of owned particle i with another owned particle and bucket n + i those with a
/// ghost; bucket_end[c] is the end of bucket c in the bond arrays, ib the other end of each bond.
struct Exclusions {
  const std::vector<std::uint32_t>* bucket_end = nullptr;
  const std::vector<std::int32_t>* other = nullptr;
  std::size_t n = 0;

  void bind(const std::vector<std::uint32_t>& end, const std::vector<std::int32_t>& ib, std::size_t n_owned) {
    bucket_end = &end;
    other = &ib;
    n = n_owned;
  }
  bool empty() const { return other == nullptr || other->empty(); }
  /// Pair (i, j) with i < j, i owned.
  bool has(std::size_t i, std::int32_t j) const {
    const auto ju = static_cast<std::size_t>(j);
    if (ju >= n) return in_bucket(n + i, j);
    return in_bucket(i, j) || in_bucket(ju, static_cast<std::int32_t>(i));
  }

 private:
  bool in_bucket(std::size_t c, std::int32_t j) const {
    const auto& e = *bucket_end;
    for (std::uint32_t k = c == 0 ? 0 : e[c - 1]; k < e[c]; ++k)
      if ((*other)[k] == j) return true;
    return false;
  }
};

/// Lists every owned-owned and owned-ghost pair closer than ri + rj + skin that `accept(i, j)` takes
/// and that is not bonded.
template <class Real, class Accept>
void build_pair_lists(const Particles<Real>& p, const CellGrid& grid, double skin, const Exclusions& ex,
                      Accept&& accept, PairList& own, PairList& ghost) {
  const std::size_t n = p.n_owned;
  own.offset.assign(n + 1, 0);
  ghost.offset.assign(n + 1, 0);
  own.neigh.clear();
  ghost.neigh.clear();
  const auto& dims = grid.dims();
  const auto& start = grid.start();
  const auto& order = grid.order();
  const Real s = Real(skin);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t c = grid.cell_of(i);
    const std::int64_t cx = c % dims[0], cy = (c / dims[0]) % dims[1], cz = c / (dims[0] * dims[1]);
    const Real xi = p.x[i], yi = p.y[i], zi = p.z[i], ri = p.radius[i] + s;
    for (std::int64_t z = std::max<std::int64_t>(cz - 1, 0); z <= std::min(cz + 1, dims[2] - 1); ++z)
      for (std::int64_t y = std::max<std::int64_t>(cy - 1, 0); y <= std::min(cy + 1, dims[1] - 1); ++y)
        for (std::int64_t x = std::max<std::int64_t>(cx - 1, 0); x <= std::min(cx + 1, dims[0] - 1); ++x) {
          const std::int64_t cell = (z * dims[1] + y) * dims[0] + x;
          // A cell lists its particles in increasing index: skip to the first j > i (owned-owned pairs
          // once; ghosts all have j >= n > i) without a per-candidate branch.
          const auto* first = order.data() + start[static_cast<std::size_t>(cell)];
          const auto* last = order.data() + start[static_cast<std::size_t>(cell) + 1];
          for (const auto* it = std::upper_bound(first, last, static_cast<std::uint32_t>(i)); it != last;
               ++it) {
            const std::uint32_t j = *it;
            const Real dx = xi - p.x[j], dy = yi - p.y[j], dz = zi - p.z[j];
            const Real cut = ri + p.radius[j];
            if (dx * dx + dy * dy + dz * dz >= cut * cut) continue;
            if (!accept(i, j)) continue;
            if (!ex.empty() && ex.has(i, static_cast<std::int32_t>(j))) continue;
            (j < n ? own : ghost).neigh.push_back(static_cast<std::int32_t>(j));
          }
        }
    own.offset[i + 1] = static_cast<std::uint32_t>(own.neigh.size());
    ghost.offset[i + 1] = static_cast<std::uint32_t>(ghost.neigh.size());
  }
  own.neigh.shrink_to_fit();
  ghost.neigh.shrink_to_fit();
}

}  // namespace basalt::solver
