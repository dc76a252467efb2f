#pragma once
// A set of particle ids for validation: a bitmap over [lo, hi] when ids are dense (the usual
// case: packers number particles 0..N-1 with few gaps), a hash set otherwise. Checking millions
// of bond ends against it costs a few ms, against tens with a binary search or hash set.
#include <cstdint>
#include <unordered_set>
#include <vector>

namespace basalt::io {

class IdSet {
 public:
  /// For `n` ids between lo and hi (inclusive).
  IdSet(std::int64_t lo, std::int64_t hi, std::size_t n) : lo_(lo) {
    const auto span = static_cast<unsigned long long>(hi) - static_cast<unsigned long long>(lo);
    dense_ = n > 0 && hi >= lo && span < 64ull * n + 4096;  // at most 64 bits per id
    if (dense_)
      bits_.resize(span + 1, false);
    else
      hash_.reserve(2 * n);
  }

  /// False when the id was already in the set.
  bool insert(std::int64_t id) {
    if (!dense_) return hash_.insert(id).second;
    auto bit = bits_[static_cast<std::size_t>(id - lo_)];
    if (bit) return false;
    bit = true;
    return true;
  }

  bool contains(std::int64_t id) const {
    if (!dense_) return hash_.count(id) > 0;
    if (id < lo_) return false;
    const auto k = static_cast<unsigned long long>(id) - static_cast<unsigned long long>(lo_);
    return k < bits_.size() && bits_[static_cast<std::size_t>(k)];
  }

 private:
  std::int64_t lo_ = 0;
  bool dense_ = false;
  std::vector<bool> bits_;
  std::unordered_set<std::int64_t> hash_;
};

}  // namespace basalt::io
