#pragma once
// The bonds a rank knows: every bond with at least one owned end. Bonds are identified by the global
// ids of their ends; at each neighbour-list rebuild the ids are resolved to local indices (ia, ib)
// and the bonds are ordered so that those with both ends owned come first ([0, n_both_owned)); in
// the others ia is the owned end and ib a ghost.
#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace basalt::solver {

template <class Real>
struct Bonds {
  std::vector<std::int64_t> a, b;    ///< global ids of the ends
  std::vector<Real> r0;              ///< rest length (the bond's history)
  std::vector<std::uint8_t> group;   ///< index of the bond's interaction group (only when grouped)
  bool grouped = false;              ///< more than one bond group: group[] is kept
  std::vector<std::int32_t> ia, ib;  ///< local indices (valid between rebuilds)
  std::size_t n_both_owned = 0;
  /// Local ends (ia, ib) of the bonds erase() removed since the caller last cleared it: their pairs
  /// become contacts (ForceField::unbond).
  std::vector<std::array<std::int32_t, 2>> parted;
  /// Changes whenever bond k may stand for another bond (push, permute, erase), never back to an earlier
  /// value (a process-wide counter): what a driver caches per bond is valid while it is unchanged.
  std::uint64_t stamp = 0;

  std::size_t size() const { return a.size(); }

  void reserve(std::size_t n) {
    a.reserve(n);
    b.reserve(n);
    r0.reserve(n);
    if (grouped) group.reserve(n);
  }

  std::uint8_t group_of(std::size_t k) const { return grouped ? group[k] : 0; }

  void push(std::int64_t ga, std::int64_t gb, Real rest, std::uint8_t g) {
    a.push_back(ga);
    b.push_back(gb);
    r0.push_back(rest);
    if (grouped) group.push_back(g);
    stamp = next_stamp();
  }

  /// Reorders: new bond k is old bond order[k]; drops the rest when order is shorter. A full
  /// permutation is applied in place (cycle by cycle, no copy of the arrays); `order` is consumed.
  void permute(std::vector<std::uint32_t>& order) {
    stamp = next_stamp();
    if (order.size() == a.size() && order.size() < (1u << 31)) {
      permute_in_place(order);
      return;
    }
    auto apply = [&](auto& v) {
      if (v.empty()) return;
      std::remove_reference_t<decltype(v)> out(order.size());
      for (std::size_t k = 0; k < order.size(); ++k) out[k] = v[order[k]];
      v.swap(out);
    };
    apply(a);
    apply(b);
    apply(r0);
    apply(group);
    apply(ia);
    apply(ib);
  }

  /// Removes the bonds at the ascending positions `gone`, keeping the others' order and n_both_owned.
  void erase(const std::vector<std::size_t>& gone) {
    std::vector<std::uint32_t> keep;
    keep.reserve(size() - gone.size());
    std::size_t g = 0, n2 = 0;
    for (std::size_t k = 0; k < size(); ++k) {
      if (g < gone.size() && gone[g] == k) {
        if (k < ia.size()) parted.push_back({ia[k], ib[k]});
        ++g;
        continue;
      }
      if (k < n_both_owned) ++n2;
      keep.push_back(static_cast<std::uint32_t>(k));
    }
    permute(keep);
    n_both_owned = n2;
  }

  /// Puts the bonds in their canonical order, a function of their local ends alone (ia the owned end,
  /// ib the other; both owned: ia < ib): both ends owned first, each part in memory order of its owned
  /// end (a counting sort, O(bonds)), then by the other end within a bucket. So the bond order, and
  /// with it the force summation order, is canonical like the particles'. Sets n_both_owned; returns
  /// the end of each bucket: bucket i holds owned particle i's bonds to owned particles, bucket
  /// n_owned + i those to ghosts (the pair-list build excludes bonded pairs through them).
  std::vector<std::uint32_t> order_canonically(std::size_t n_owned) {
    const std::size_t nb = size(), n = n_owned;
    std::vector<std::uint32_t> start(2 * n + 1, 0);
    auto key = [&](std::size_t k) {
      return (static_cast<std::size_t>(ib[k]) >= n ? n : 0) + static_cast<std::size_t>(ia[k]);
    };
    for (std::size_t k = 0; k < nb; ++k) ++start[key(k) + 1];
    for (std::size_t c = 0; c < 2 * n; ++c) start[c + 1] += start[c];
    std::vector<std::uint32_t> order(nb);
    for (std::size_t k = 0; k < nb; ++k) order[start[key(k)]++] = static_cast<std::uint32_t>(k);
    for (std::size_t c = 0, first = 0; c < 2 * n; first = start[c], ++c)
      if (start[c] - first > 1)
        std::sort(order.begin() + static_cast<std::ptrdiff_t>(first), order.begin() + start[c],
                  [&](std::uint32_t i, std::uint32_t j) { return ib[i] < ib[j]; });
    permute(order);
    n_both_owned = 0;
    while (n_both_owned < nb && static_cast<std::size_t>(ib[n_both_owned]) < n) ++n_both_owned;
    return start;  // start[c] is now the end of bucket c
  }

 private:
  static std::uint64_t next_stamp() {
    static std::atomic<std::uint64_t> counter{0};
    return counter.fetch_add(1, std::memory_order_relaxed) + 1;
  }

  void permute_in_place(std::vector<std::uint32_t>& order) {
    constexpr std::uint32_t kDone = 1u << 31;
    const bool has_local = !ia.empty(), has_group = !group.empty();
    for (std::size_t s = 0; s < order.size(); ++s) {
      if (order[s] & kDone) continue;
      // Walk the cycle through s: position j receives the element at order[j].
      const auto ta = a[s], tb = b[s];
      const auto tr = r0[s];
      const auto tg = has_group ? group[s] : std::uint8_t{0};
      const auto tia = has_local ? ia[s] : 0, tib = has_local ? ib[s] : 0;
      std::size_t j = s;
      for (;;) {
        const std::size_t k = order[j];
        order[j] |= kDone;
        if (k == s) break;
        a[j] = a[k];
        b[j] = b[k];
        r0[j] = r0[k];
        if (has_group) group[j] = group[k];
        if (has_local) {
          ia[j] = ia[k];
          ib[j] = ib[k];
        }
        j = k;
      }
      a[j] = ta;
      b[j] = tb;
      r0[j] = tr;
      if (has_group) group[j] = tg;
      if (has_local) {
        ia[j] = tia;
        ib[j] = tib;
      }
    }
  }
};

}  // namespace basalt::solver
