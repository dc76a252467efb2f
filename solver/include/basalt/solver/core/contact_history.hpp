#pragma once
// Per-contact history in transit: the state a contact model keeps for a pair (e.g. a tangential spring),
// keyed by the global ids of the pair, as it travels across a neighbour-list rebuild (the lists are
// rebuilt, the pairs are found again by id), with migrating particles to their new rank, and to and
// from checkpoints. Values belong to the orientation a -> b in which they were saved; a model whose
// history changes sign with the orientation says so (Model::flip), the driver applies it.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

namespace basalt::solver {

struct ContactRecords {
  std::size_t width = 0;  ///< doubles per record (the model's History)
  std::vector<std::int64_t> a, b;
  std::vector<double> values;  ///< width per record

  std::size_t size() const { return a.size(); }
  bool empty() const { return a.empty(); }
  void clear() {
    a.clear();
    b.clear();
    values.clear();
  }
  void push(std::int64_t ia, std::int64_t ib, const double* v) {
    a.push_back(ia);
    b.push_back(ib);
    values.insert(values.end(), v, v + width);
  }
  const double* at(std::size_t k) const { return values.data() + k * width; }

  /// Records ordered by their unordered pair (lower id, higher id), in saved order within a pair: the
  /// mesh walls' look-up of all records of a pair (ContactLookup finds the one record a pair keeps).
  void index(std::vector<std::uint32_t>& order) const {
    order.resize(size());
    for (std::uint32_t k = 0; k < order.size(); ++k) order[k] = k;
    std::sort(order.begin(), order.end(), [&](std::uint32_t i, std::uint32_t j) {
      const auto ki = key(i), kj = key(j);
      return ki != kj ? ki < kj : i < j;
    });
  }

 private:
  std::pair<std::int64_t, std::int64_t> key(std::size_t k) const {
    return {std::min(a[k], b[k]), std::max(a[k], b[k])};
  }
};

/// The record a pair takes back at a rebuild, through a hash table on the unordered pair (a sort and a
/// binary search per pair were 4 % of a granular run). A pair between two ranks is listed on both, each as
/// (owned, ghost), and each rank's history of it is its own: computed with the pair's roles swapped, it is
/// the other's flipped only to rounding. Both are kept (checkpoints, migration), and each rank takes back
/// its own, so a restart continues bit for bit (docs/solver.md). A slot holds two record numbers (8 B; 16 B
/// per record at half load), the pair's ids are read from the records: it refers to `r`, which must outlive
/// it.
class ContactLookup {
 public:
  explicit ContactLookup(const ContactRecords& r) : r_(r) {
    std::size_t cap = 16;
    while (cap < 2 * r.size()) cap <<= 1;
    slots_.assign(cap, Slot{});
    mask_ = cap - 1;
    for (std::size_t k = 0; k < r.size(); ++k) {
      const std::int64_t lo = std::min(r.a[k], r.b[k]), hi = std::max(r.a[k], r.b[k]);
      Slot& s = slots_[probe(lo, hi)];
      std::int32_t& first = r.a[k] == lo ? s.fwd : s.bwd;  // saved as lo -> hi, or as hi -> lo
      if (first < 0) first = static_cast<std::int32_t>(k);
    }
  }
  /// The record of the pair {ia, ib}, or -1: the first one saved in the orientation ia -> ib if there
  /// is one, else the first in the other.
  std::int64_t find(std::int64_t ia, std::int64_t ib) const {
    const std::int64_t lo = std::min(ia, ib), hi = std::max(ia, ib);
    const Slot& s = slots_[probe(lo, hi)];
    const std::int32_t mine = ia == lo ? s.fwd : s.bwd, other = ia == lo ? s.bwd : s.fwd;
    return mine >= 0 ? mine : other;
  }

 private:
  struct Slot {
    std::int32_t fwd = -1, bwd = -1;  ///< first record in each orientation; both -1: an empty slot
  };
  /// The slot of the pair, or the empty slot where it would go (linear probing; never full).
  std::size_t probe(std::int64_t lo, std::int64_t hi) const {
    std::uint64_t h = std::uint64_t(lo) * 0x9E3779B97F4A7C15ull + std::uint64_t(hi);
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 32;
    for (std::size_t at = h & mask_;; at = (at + 1) & mask_) {
      const Slot& s = slots_[at];
      const std::int32_t k = s.fwd >= 0 ? s.fwd : s.bwd;
      if (k < 0) return at;
      const auto u = static_cast<std::size_t>(k);
      if (std::min(r_.a[u], r_.b[u]) == lo && std::max(r_.a[u], r_.b[u]) == hi) return at;
    }
  }
  const ContactRecords& r_;
  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
};

}  // namespace basalt::solver
