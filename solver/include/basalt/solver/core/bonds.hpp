#pragma once
// The bonds a rank knows: every bond with at least one owned end. Bonds are identified by the global
// ids of their ends; at each neighbour-list rebuild the ids are resolved to local indices (ia, ib)
// and the bonds are ordered so that those with both ends owned come first ([0, n_both_owned)); in
// the others ia is the owned end and ib a ghost.
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
  }

  /// Reorders: new bond k is old bond order[k]; drops the rest when order is shorter. A full
  /// permutation is applied in place (cycle by cycle, no copy of the arrays); `order` is consumed.
  void permute(std::vector<std::uint32_t>& order) {
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

 private:
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
