#pragma once
// Loops a contact model over the Verlet pair lists. Owned-owned pairs apply Newton's third law once;
// owned-ghost pairs give force to the owned particle only. Energies are tallied by the rank owning the
// smaller global id. With one group that takes every tag the per-pair group lookup is skipped.
#include <cmath>
#include <cstdint>
#include <vector>

#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/neighbor/verlet_list.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::solver {

template <class Real, class Model>
class PairDriver {
 public:
  explicit PairDriver(const std::vector<Group<Model>>& groups) : groups_(groups) {
    for (const auto& g : groups) K_.push_back(Real(g.params.K));
    uniform_ = groups.size() == 1 && groups[0].tags.empty();
  }

  bool empty() const { return groups_.empty(); }
  /// One group for every pair of tags.
  bool takes_all() const { return uniform_; }

  /// Group index taking a pair of particles with these tags, or -1.
  int group_of(std::int64_t ti, std::int64_t tj) const {
    for (std::size_t g = 0; g < groups_.size(); ++g) {
      const auto& t = groups_[g].tags;
      if (t.empty() || (t[0] == ti && t[1] == tj) || (t[0] == tj && t[1] == ti)) return static_cast<int>(g);
    }
    return -1;
  }

  template <bool Energy>
  double compute(Particles<Real>& p, const PairList& own, const PairList& ghost) const {
    if (uniform_) return loop<Energy, true>(p, own, ghost);
    return loop<Energy, false>(p, own, ghost);
  }

  Real max_stiffness() const {
    Real m = 0;
    for (auto k : K_) m = std::max(m, k);
    return m;
  }

 private:
  template <bool Energy, bool Uniform>
  double loop(Particles<Real>& p, const PairList& own, const PairList& ghost) const {
    double energy = 0;
    const std::size_t n = p.n_owned;
    const Real* x = p.x.data();
    const Real* y = p.y.data();
    const Real* z = p.z.data();
    const Real* rad = p.radius.data();
    Real* fx = p.fx.data();
    Real* fy = p.fy.data();
    Real* fz = p.fz.data();
    const Real K0 = K_.empty() ? Real(0) : K_[0];
    for (std::size_t i = 0; i < n; ++i) {
      const Real xi = x[i], yi = y[i], zi = z[i], ri = rad[i];
      Real fxi = 0, fyi = 0, fzi = 0;
      for (int pass = 0; pass < 2; ++pass) {
        const PairList& list = pass == 0 ? own : ghost;
        for (auto k = list.offset[i]; k < list.offset[i + 1]; ++k) {
          const auto j = static_cast<std::size_t>(list.neigh[k]);
          const Real dx = xi - x[j], dy = yi - y[j], dz = zi - z[j];
          const Real r2 = dx * dx + dy * dy + dz * dz;
          const Real rsum = ri + rad[j];
          if (!Model::touching(r2, rsum)) continue;
          Real K = K0;
          if constexpr (!Uniform) {
            const int g = group_of(p.tag[i], p.tag[j]);
            K = K_[static_cast<std::size_t>(g)];
          }
          const Real r = std::sqrt(r2);
          const Real s = Model::force(K, rsum, r) / r;
          fxi += s * dx;
          fyi += s * dy;
          fzi += s * dz;
          if (pass == 0) {
            fx[j] -= s * dx;
            fy[j] -= s * dy;
            fz[j] -= s * dz;
          }
          if constexpr (Energy)
            if (pass == 0 || p.id[i] < p.id[j]) energy += double(Model::energy(K, rsum, r));
        }
      }
      fx[i] += fxi;
      fy[i] += fyi;
      fz[i] += fzi;
    }
    return energy;
  }

  std::vector<Group<Model>> groups_;
  std::vector<Real> K_;
  bool uniform_ = false;
};

}  // namespace basalt::solver
