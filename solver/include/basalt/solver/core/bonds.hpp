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
  std::vector<std::int64_t> a, b;  ///< global ids of the ends
  std::vector<Real> r0;            ///< rest length (the bond's history)
  std::vector<std::uint8_t> group;  ///< index of the bond's interaction group
  std::vector<std::int32_t> ia, ib;  ///< local indices (valid between rebuilds)
  std::size_t n_both_owned = 0;

  std::size_t size() const { return a.size(); }

  void reserve(std::size_t n) {
    a.reserve(n);
    b.reserve(n);
    r0.reserve(n);
    group.reserve(n);
  }

  void push(std::int64_t ga, std::int64_t gb, Real rest, std::uint8_t g) {
    a.push_back(ga);
    b.push_back(gb);
    r0.push_back(rest);
    group.push_back(g);
  }

  /// Reorders: new bond k is old bond order[k]; drops the rest when order is shorter.
  void permute(const std::vector<std::uint32_t>& order) {
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
};

}  // namespace basalt::solver
