#pragma once
// Loops a bond model over the rank's bonds. Bonds with both ends owned apply Newton's third law once;
// bonds to a ghost apply the force to the owned end only (the ghost's owner computes the same bond
// from identical positions, so both ranks also agree when it breaks). Energies and counts are tallied
// by the rank owning the smaller global id, so sums over ranks count each bond once.
#include <cmath>
#include <cstdint>
#include <vector>

#include "basalt/solver/core/bonds.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::solver {

struct BrokenBond {
  std::int64_t a, b;
  double length, rest_length;
  std::int64_t step = -1;  ///< the step it broke at (set by the simulation)
  std::uint8_t group = 0;  ///< its interaction group: a restart at that very step restores the bond
};

template <class Real, class Model>
class BondDriver {
 public:
  explicit BondDriver(const std::vector<Group<Model>>& groups) {
    for (const auto& g : groups) {
      K_.push_back(Real(g.params.K));
      eps_.push_back(std::isfinite(g.params.break_strain) ? Real(g.params.break_strain)
                                                          : std::numeric_limits<Real>::infinity());
      breakable_ = breakable_ || std::isfinite(g.params.break_strain);
    }
  }

  /// Adds bond forces to p.f*; returns the bond potential energy (when Energy) and appends bonds
  /// that broke (they are removed at once).
  template <bool Energy>
  double compute(Particles<Real>& p, Bonds<Real>& bonds, std::vector<BrokenBond>& broken) {
    const double e =
        compute_part<Energy, true>(p, bonds, broken) + compute_part<Energy, false>(p, bonds, broken);
    commit(bonds);
    return e;
  }

  /// Bonds with both ends owned (BothOwned) or with a ghost end; call commit() after both parts.
  template <bool Energy, bool BothOwned>
  double compute_part(Particles<Real>& p, const Bonds<Real>& bonds, std::vector<BrokenBond>& broken) {
    if (BothOwned) gone_.clear();
    const std::size_t b = BothOwned ? 0 : bonds.n_both_owned,
                      e = BothOwned ? bonds.n_both_owned : bonds.size();
    if (K_.size() == 1 && !breakable_) return loop<Energy, true, false, BothOwned>(p, bonds, broken, b, e);
    if (K_.size() == 1) return loop<Energy, true, true, BothOwned>(p, bonds, broken, b, e);
    return loop<Energy, false, true, BothOwned>(p, bonds, broken, b, e);
  }

  /// Removes the bonds that broke in this step's compute_part() calls.
  void commit(Bonds<Real>& bonds) {
    if (!gone_.empty()) remove(bonds, gone_);
    gone_.clear();
  }

  /// Bonds counted once across ranks.
  static std::int64_t count(const Particles<Real>& p, const Bonds<Real>& bonds) {
    std::int64_t c = static_cast<std::int64_t>(bonds.n_both_owned);
    for (std::size_t k = bonds.n_both_owned; k < bonds.size(); ++k)
      c += p.id[static_cast<std::size_t>(bonds.ia[k])] < p.id[static_cast<std::size_t>(bonds.ib[k])];
    return c;
  }

  Real max_stiffness() const {
    Real m = 0;
    for (auto k : K_) m = std::max(m, k);
    return m;
  }

 private:
  template <bool Energy, bool Uniform, bool Breakable, bool BothOwned>
  double loop(Particles<Real>& p, const Bonds<Real>& bonds, std::vector<BrokenBond>& broken,
              std::size_t begin, std::size_t end) {
    double energy = 0;
    const Real* __restrict x = p.x.data();
    const Real* __restrict y = p.y.data();
    const Real* __restrict z = p.z.data();
    Real* __restrict fx = p.fx.data();
    Real* __restrict fy = p.fy.data();
    Real* __restrict fz = p.fz.data();
    const std::int32_t* __restrict ia = bonds.ia.data();
    const std::int32_t* __restrict ib = bonds.ib.data();
    const Real* __restrict r0s = bonds.r0.data();
    const Real K0 = K_[0], eps0 = eps_[0];
    for (std::size_t k = begin; k < end; ++k) {
      const auto i = static_cast<std::size_t>(ia[k]), j = static_cast<std::size_t>(ib[k]);
      const Real dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
      const Real r = std::sqrt(dx * dx + dy * dy + dz * dz);
      const Real r0 = r0s[k];
      const std::size_t g = Uniform ? 0 : bonds.group[k];
      const Real K = Uniform ? K0 : K_[g];
      if constexpr (Breakable) {
        if (Model::broken(Uniform ? eps0 : eps_[g], r0, r)) [[unlikely]] {
          gone_.push_back(k);
          if (BothOwned || p.id[i] < p.id[j])
            broken.push_back({bonds.a[k], bonds.b[k], double(r), double(r0), -1, bonds.group_of(k)});
          continue;
        }
      }
      const Real s = Model::force(K, r0, r) / r;
      fx[i] += s * dx;
      fy[i] += s * dy;
      fz[i] += s * dz;
      if constexpr (BothOwned) {
        fx[j] -= s * dx;
        fy[j] -= s * dy;
        fz[j] -= s * dz;
      }
      if constexpr (Energy)
        if (BothOwned || p.id[i] < p.id[j]) energy += double(Model::energy(K, r0, r));
    }
    return energy;
  }

  static void remove(Bonds<Real>& bonds, const std::vector<std::size_t>& gone) {
    std::vector<std::uint32_t> keep;
    keep.reserve(bonds.size() - gone.size());
    std::size_t g = 0, n2 = 0;
    for (std::size_t k = 0; k < bonds.size(); ++k) {
      if (g < gone.size() && gone[g] == k) {
        ++g;
        continue;
      }
      if (k < bonds.n_both_owned) ++n2;
      keep.push_back(static_cast<std::uint32_t>(k));
    }
    bonds.permute(keep);
    bonds.n_both_owned = n2;
  }

  std::vector<Real> K_, eps_;
  bool breakable_ = false;
  std::vector<std::size_t> gone_;
};

}  // namespace basalt::solver
