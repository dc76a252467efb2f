#pragma once
// Contact history as records (core/contact_history.hpp), written once for the contact drivers: which
// histories hold something, the records of a pair list's or a wall's contacts, and the histories found
// again from the pending records after a rebuild. A pair's record is (id of the listed particle, id of
// its neighbour), flipped (Model::flip) when found the other way round; a wall contact's is (particle id,
// wall_record_id(index)), index counting the planar walls, then the mesh walls (docs/formats.md).
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "basalt/solver/core/contact_history.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/neighbor/verlet_list.hpp"

namespace basalt::solver {

/// Whether a contact history holds anything (a bit set). Every model's apart() clears its history to all
/// bits zero, and a clear history parts with no energy, so a pair apart whose history is clear needs
/// neither; only histories that hold something are saved. (Bits, not values: a -0 is cleared to +0.)
template <class History>
inline bool holds(const History& h) {
  static_assert(std::is_trivially_copyable_v<History> && sizeof(History) % sizeof(std::uint64_t) == 0);
  std::uint64_t w[sizeof(History) / sizeof(std::uint64_t)];
  std::memcpy(w, &h, sizeof(History));
  std::uint64_t any = 0;
  for (const auto v : w) any |= v;
  return any != 0;
}

/// The second id of a wall contact's record: -1 - the wall's index (planar walls, then mesh walls).
inline std::int64_t wall_record_id(std::size_t index) { return -1 - static_cast<std::int64_t>(index); }

/// Records of the listed pairs whose history holds something, in the listed orientation.
template <class Model, class Real, class History>
void collect_pairs(const Particles<Real>& p, const PairList& list, const std::vector<History>& hist,
                   ContactRecords& out) {
  out.width = history_width<Model>();
  for (std::size_t i = 0; i + 1 < list.offset.size(); ++i)
    for (auto k = list.offset[i]; k < list.offset[i + 1]; ++k)
      if (holds(hist[k]))
        out.push(p.id[i], p.id[static_cast<std::size_t>(list.neigh[k])],
                 reinterpret_cast<const double*>(&hist[k]));
}

/// History for each listed pair from the pending records (default when none).
template <class Model, class Real, class History>
void restore_pairs(const Particles<Real>& p, const PairList& list, const ContactRecords& pending,
                   const ContactLookup& records, std::vector<History>& hist) {
  hist.assign(list.pairs(), History{});
  if (pending.empty()) return;
  for (std::size_t i = 0; i + 1 < list.offset.size(); ++i)
    for (auto k = list.offset[i]; k < list.offset[i + 1]; ++k) {
      const auto r = records.find(p.id[i], p.id[static_cast<std::size_t>(list.neigh[k])]);
      if (r < 0) continue;
      std::memcpy(static_cast<void*>(&hist[k]), pending.at(static_cast<std::size_t>(r)), sizeof(History));
      if (pending.a[static_cast<std::size_t>(r)] != p.id[i]) hist[k] = Model::flip(hist[k]);
    }
}

/// Records of a wall's candidates (particle indices) whose history holds something.
template <class Real, class History>
void collect_candidates(const Particles<Real>& p, const std::vector<std::int32_t>& cand,
                        const std::vector<History>& hist, std::int64_t wall_id, ContactRecords& out) {
  for (std::size_t c = 0; c < cand.size() && c < hist.size(); ++c)
    if (holds(hist[c]))
      out.push(p.id[static_cast<std::size_t>(cand[c])], wall_id, reinterpret_cast<const double*>(&hist[c]));
}

/// History for each of a wall's candidates from the pending records (default when none).
template <class Real, class History>
void restore_candidates(const Particles<Real>& p, const std::vector<std::int32_t>& cand,
                        const ContactRecords& pending, const ContactLookup& records, std::int64_t wall_id,
                        std::vector<History>& hist) {
  hist.assign(cand.size(), History{});
  if (pending.empty()) return;
  for (std::size_t c = 0; c < cand.size(); ++c) {
    const auto r = records.find(p.id[static_cast<std::size_t>(cand[c])], wall_id);
    if (r >= 0)
      std::memcpy(static_cast<void*>(&hist[c]), pending.at(static_cast<std::size_t>(r)), sizeof(History));
  }
}

}  // namespace basalt::solver
