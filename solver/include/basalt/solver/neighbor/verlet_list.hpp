#pragma once
// Verlet pair lists with a skin, built over a cell grid at each rebuild. Half lists: a pair of owned
// particles appears once (i < j, Newton's third law applies); a pair of an owned particle and a ghost
// appears in the ghost list of the owned one (the owning rank of the ghost lists it too; each rank
// applies the force to its own particle only). Bonded pairs are excluded (they interact by their bond),
// or, where bonds can break, listed and marked bonded: a pair whose bond breaks is then a contact at the
// next step without a rebuild (PairList::unbond).
#include <algorithm>
#include <cstdint>
#include <vector>

#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/neighbor/cell_grid.hpp"

namespace basalt::solver {

/// Compressed rows over owned particles: neighbours of i are neigh[offset[i] .. offset[i+1]). With
/// bonded pairs listed (`bonded` not empty), bonded[e] is 1 while entry e's pair is bonded: the pair
/// models pass over it as over a pair apart. They step over the entries of the pairs not bonded alone:
/// loose[loose_offset[i] .. loose_offset[i+1]) are row i's, in list order (in an intact rock most listed
/// pairs are bonded).
struct PairList {
  std::vector<std::uint32_t> offset;
  std::vector<std::int32_t> neigh;
  std::vector<std::uint8_t> bonded;  ///< empty: bonded pairs are not listed at all
  std::size_t pairs() const { return neigh.size(); }
  std::vector<std::uint32_t> loose_offset, loose;  ///< with bonded marks: the entries not bonded, by row
  bool is_bonded(std::size_t e) const { return !bonded.empty() && bonded[e] != 0; }
  /// loose_offset and loose from the marks (after the list is built, or its marks are set).
  void index_loose() {
    loose_offset.clear();
    loose.clear();
    if (bonded.empty()) return;
    const std::size_t n = offset.empty() ? 0 : offset.size() - 1;
    loose_offset.assign(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
      for (auto e = offset[i]; e < offset[i + 1]; ++e)
        if (bonded[e] == 0) loose.push_back(e);
      loose_offset[i + 1] = static_cast<std::uint32_t>(loose.size());
    }
  }
  /// The bond of listed pair (i, j) broke (i owned; j owned or a ghost): from now on it is a contact.
  /// Returns whether the pair was listed (a pair beyond its cutoff at the last rebuild cannot touch
  /// before the next one).
  bool unbond(std::size_t i, std::size_t j) {
    if (bonded.empty()) return false;
    if (loose_offset.size() != offset.size()) index_loose();  // (a list whose marks were set by hand)
    const auto clear_in_row = [&](std::size_t row, std::size_t other) {
      if (row + 1 >= offset.size()) return false;
      for (auto e = offset[row]; e < offset[row + 1]; ++e)
        if (static_cast<std::size_t>(neigh[e]) == other) {
          if (bonded[e] != 0) {
            bonded[e] = 0;
            // e joins its row's loose entries, in list order.
            const auto first = loose.begin() + loose_offset[row],
                       last = loose.begin() + loose_offset[row + 1];
            loose.insert(std::lower_bound(first, last, e), e);
            for (auto k = row + 1; k < loose_offset.size(); ++k) ++loose_offset[k];
          }
          return true;
        }
      return false;
    };
    return clear_in_row(i, j) || clear_in_row(j, i);
  }
  std::size_t memory_bytes() const {
    return (offset.capacity() + loose_offset.capacity() + loose.capacity()) * sizeof(std::uint32_t) +
           neigh.capacity() * sizeof(std::int32_t) + bonded.capacity();
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
/// and that is not bonded (with `mark_bonded`: bonded too, marked in PairList::bonded). `owned` holds the
/// owned particles [0, n_owned), `ghosts` (the same cells) the ghosts. Cells may be narrower than the longest
/// cutoff: particle i looks as far as it can interact, ri + skin + the largest radius, so a small sphere
/// (most of a power-law packing) searches a small box. Each owned-owned pair is listed once, from the
/// particle in the lower cell (cells ordered z, y, x: the upper half of the box) or, in one cell, from the
/// lower index; a ghost from the whole box. Rows of cells along x are single ranges of the cell order,
/// scanned without a per-cell step.
template <class Real, class Accept>
void build_pair_lists(const Particles<Real>& p, const CellGrid& owned, const CellGrid& ghosts, double skin,
                      const Exclusions& ex, Accept&& accept, PairList& own, PairList& ghost,
                      bool mark_bonded = false) {
  const std::size_t n = p.n_owned;
  own.offset.assign(n + 1, 0);
  ghost.offset.assign(n + 1, 0);
  own.neigh.clear();
  ghost.neigh.clear();
  own.bonded.clear();
  ghost.bonded.clear();
  const bool exclude = !ex.empty() && !mark_bonded;
  const Real s = Real(skin);
  const Real rmax = p.size() == 0 ? Real(0) : *std::max_element(p.radius.begin(), p.radius.end());
  const auto& dims = owned.dims();
  const auto& ostart = owned.start();
  const auto& gstart = ghosts.start();
  const std::uint32_t* oorder = owned.order().data();
  const std::uint32_t* gorder = ghosts.order().data();
  for (std::size_t i = 0; i < n; ++i) {
    const Real xi = p.x[i], yi = p.y[i], zi = p.z[i], ri = p.radius[i] + s, reach = ri + rmax;
    const auto scan = [&](const std::uint32_t* it, const std::uint32_t* last, PairList& list) {
      for (; it != last; ++it) {
        const std::uint32_t j = *it;
        const Real dx = xi - p.x[j], dy = yi - p.y[j], dz = zi - p.z[j];
        const Real cut = ri + p.radius[j];
        if (dx * dx + dy * dy + dz * dz >= cut * cut) continue;
        if (!accept(i, j)) continue;
        if (exclude && ex.has(i, static_cast<std::int32_t>(j))) continue;
        list.neigh.push_back(static_cast<std::int32_t>(j));
      }
    };
    const std::int64_t x0 = owned.coord(0, double(xi - reach)), x1 = owned.coord(0, double(xi + reach));
    const std::int64_t y0 = owned.coord(1, double(yi - reach)), y1 = owned.coord(1, double(yi + reach));
    const std::int64_t z0 = owned.coord(2, double(zi - reach)), z1 = owned.coord(2, double(zi + reach));
    const std::int64_t c = owned.cell_of(i);
    const std::int64_t cy = (c / dims[0]) % dims[1], cz = c / (dims[0] * dims[1]);
    // The rest of i's own row: i's cell after i (a cell lists its particles in increasing index), then
    // the cells after it.
    const std::int64_t row = (cz * dims[1] + cy) * dims[0];
    const auto* first = oorder + ostart[static_cast<std::size_t>(c)];
    const auto* last = oorder + ostart[static_cast<std::size_t>(c) + 1];
    scan(std::upper_bound(first, last, static_cast<std::uint32_t>(i)),
         oorder + ostart[static_cast<std::size_t>(row + x1) + 1], own);
    for (std::int64_t z = cz; z <= z1; ++z)
      for (std::int64_t y = z == cz ? cy + 1 : y0; y <= y1; ++y) {
        const auto r = static_cast<std::size_t>((z * dims[1] + y) * dims[0]);
        scan(oorder + ostart[r + static_cast<std::size_t>(x0)],
             oorder + ostart[r + static_cast<std::size_t>(x1) + 1], own);
      }
    if (gstart.size() > 1 && gstart.back() > 0)
      for (std::int64_t z = z0; z <= z1; ++z)
        for (std::int64_t y = y0; y <= y1; ++y) {
          const auto r = static_cast<std::size_t>((z * dims[1] + y) * dims[0]);
          scan(gorder + gstart[r + static_cast<std::size_t>(x0)],
               gorder + gstart[r + static_cast<std::size_t>(x1) + 1], ghost);
        }
    // In memory order: the force loop then walks the neighbours' data forward.
    std::sort(own.neigh.begin() + own.offset[i], own.neigh.end());
    own.offset[i + 1] = static_cast<std::uint32_t>(own.neigh.size());
    ghost.offset[i + 1] = static_cast<std::uint32_t>(ghost.neigh.size());
    if (mark_bonded)
      for (PairList* list : {&own, &ghost})
        for (auto e = list->bonded.size(); e < list->neigh.size(); ++e)
          list->bonded.push_back(!ex.empty() && ex.has(i, list->neigh[e]) ? 1 : 0);
  }
  own.neigh.shrink_to_fit();
  ghost.neigh.shrink_to_fit();
  own.bonded.shrink_to_fit();
  ghost.bonded.shrink_to_fit();
  own.index_loose();
  ghost.index_loose();
}

}  // namespace basalt::solver
