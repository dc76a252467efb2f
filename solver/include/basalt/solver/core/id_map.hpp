#pragma once
// Global id -> local index, rebuilt at each neighbour-list rebuild. A direct table over the global id
// range when ids are dense enough (4 bytes per id), a hash map otherwise.
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace basalt::solver {

class IdMap {
 public:
  /// min_id/max_id: the global id range; ids outside it are never inserted.
  void configure(std::int64_t min_id, std::int64_t max_id, std::size_t n_global) {
    min_ = min_id;
    const auto range = static_cast<std::uint64_t>(max_id - min_id) + 1;
    dense_ = range <= 4 * static_cast<std::uint64_t>(n_global) + 1024;
    if (dense_) table_.assign(range, -1);
  }
  /// Maps ids[0..n) -> 0..n). Valid while `ids` is unchanged (stale table entries from earlier
  /// calls are harmless: find() checks the id at the index it returns).
  void assign(const std::vector<std::int64_t>& ids, std::size_t n) {
    hash_.clear();
    if (!dense_) hash_.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (dense_)
        table_[static_cast<std::size_t>(ids[i] - min_)] = static_cast<std::int32_t>(i);
      else
        hash_[ids[i]] = static_cast<std::int32_t>(i);
    }
    ids_ = &ids;
    n_ = n;
  }
  /// Local index or -1.
  std::int32_t find(std::int64_t gid) const {
    if (dense_) {
      const auto k = gid - min_;
      if (k < 0 || static_cast<std::size_t>(k) >= table_.size()) return -1;
      const auto i = table_[static_cast<std::size_t>(k)];
      return i >= 0 && static_cast<std::size_t>(i) < n_ && (*ids_)[static_cast<std::size_t>(i)] == gid ? i : -1;
    }
    auto it = hash_.find(gid);
    return it == hash_.end() ? -1 : it->second;
  }
  std::size_t memory_bytes() const { return table_.capacity() * sizeof(std::int32_t) + hash_.size() * 32; }

 private:
  bool dense_ = false;
  std::int64_t min_ = 0;
  std::vector<std::int32_t> table_;
  std::unordered_map<std::int64_t, std::int32_t> hash_;
  const std::vector<std::int64_t>* ids_ = nullptr;
  std::size_t n_ = 0;
};

}  // namespace basalt::solver
