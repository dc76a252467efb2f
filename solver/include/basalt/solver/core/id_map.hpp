#pragma once
// Global id -> local index, rebuilt at each neighbour-list rebuild. Stores only local indices
// (4 bytes per slot); the id itself is read back from the particle array to confirm a hit.
//  - dense ids (range <= 8 x count): a direct table over the global id range;
//  - sparse ids (GenGeo's are): open addressing with linear probing, 1.4-2.8 slots per local particle.
#include <cstdint>
#include <vector>

namespace basalt::solver {

class IdMap {
 public:
  /// min_id/max_id: the global id range; n_global: the number of particles.
  void configure(std::int64_t min_id, std::int64_t max_id, std::size_t n_global) {
    min_ = min_id;
    const auto range = static_cast<std::uint64_t>(max_id - min_id) + 1;
    dense_ = range <= 8 * static_cast<std::uint64_t>(n_global) + 1024;
    if (dense_) table_.assign(range, -1);
  }

  /// The same lowest id, a new highest id and count (particles inserted with new ids).
  void grow(std::int64_t max_id, std::size_t n_global) { configure(min_, max_id, n_global); }

  /// Maps ids[0..n) -> 0..n). Valid while `ids` is unchanged.
  void assign(const std::vector<std::int64_t>& ids, std::size_t n) {
    ids_ = &ids;
    n_ = n;
    if (dense_) {
      for (std::size_t i = 0; i < n; ++i)
        table_[static_cast<std::size_t>(ids[i] - min_)] = static_cast<std::int32_t>(i);
      return;
    }
    std::size_t cap = 16;
    while (10 * cap < 14 * n) cap *= 2;  // load factor <= 0.71
    mask_ = cap - 1;
    table_.assign(cap, -1);
    for (std::size_t i = 0; i < n; ++i) {
      std::size_t s = slot(ids[i]);
      while (table_[s] >= 0) s = (s + 1) & mask_;
      table_[s] = static_cast<std::int32_t>(i);
    }
  }

  /// Local index or -1.
  std::int32_t find(std::int64_t gid) const {
    if (dense_) {
      const auto k = gid - min_;
      if (k < 0 || static_cast<std::size_t>(k) >= table_.size()) return -1;
      const auto i = table_[static_cast<std::size_t>(k)];  // stale entries from earlier calls are checked
      return i >= 0 && static_cast<std::size_t>(i) < n_ && (*ids_)[static_cast<std::size_t>(i)] == gid ? i
                                                                                                       : -1;
    }
    for (std::size_t s = slot(gid);; s = (s + 1) & mask_) {
      const auto i = table_[s];
      if (i < 0) return -1;
      if ((*ids_)[static_cast<std::size_t>(i)] == gid) return i;
    }
  }

  std::size_t memory_bytes() const { return table_.capacity() * sizeof(std::int32_t); }

 private:
  std::size_t slot(std::int64_t gid) const {
    auto k = static_cast<std::uint64_t>(gid) * 0x9E3779B97F4A7C15ull;
    return static_cast<std::size_t>(k >> 20) & mask_;
  }

  bool dense_ = false;
  std::int64_t min_ = 0;
  std::size_t mask_ = 0;
  std::vector<std::int32_t> table_;
  const std::vector<std::int64_t>* ids_ = nullptr;
  std::size_t n_ = 0;
};

}  // namespace basalt::solver
