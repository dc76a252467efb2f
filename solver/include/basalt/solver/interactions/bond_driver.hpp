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
};

template <class Real, class Model>
class BondDriver {
 public:
  explicit BondDriver(const std::vector<Group<Model>>& groups) {
    for (const auto& g : groups) {
      K_.push_back(Real(g.params.K));
      eps_.push_back(std::isfinite(g.params.break_strain) ? Real(g.params.break_strain)
                                                          : std::numeric_limits<Real>::infinity());
    }
  }

  /// Adds bond forces to p.f*; returns the bond potential energy (when Energy) and appends bonds
  /// that broke (they are removed at once).
  template <bool Energy>
  double compute(Particles<Real>& p, Bonds<Real>& bonds, std::vector<BrokenBond>& broken) {
    double energy = 0;
    const std::size_t nb = bonds.size(), n2 = bonds.n_both_owned;
    const Real* x = p.x.data();
    const Real* y = p.y.data();
    const Real* z = p.z.data();
    Real* fx = p.fx.data();
    Real* fy = p.fy.data();
    Real* fz = p.fz.data();
    const bool uniform = K_.size() == 1;
    std::vector<std::size_t> gone;
    for (std::size_t k = 0; k < nb; ++k) {
      const auto i = static_cast<std::size_t>(bonds.ia[k]), j = static_cast<std::size_t>(bonds.ib[k]);
      const Real dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
      const Real r = std::sqrt(dx * dx + dy * dy + dz * dz);
      const std::size_t g = uniform ? 0 : bonds.group[k];
      const Real r0 = bonds.r0[k];
      if (Model::broken(eps_[g], r0, r)) [[unlikely]] {
        gone.push_back(k);
        if (k < n2 || p.id[i] < p.id[j]) broken.push_back({bonds.a[k], bonds.b[k], double(r), double(r0)});
        continue;
      }
      const Real s = Model::force(K_[g], r0, r) / r;
      fx[i] += s * dx;
      fy[i] += s * dy;
      fz[i] += s * dz;
      if (k < n2) {
        fx[j] -= s * dx;
        fy[j] -= s * dy;
        fz[j] -= s * dz;
      }
      if constexpr (Energy)
        if (k < n2 || p.id[i] < p.id[j]) energy += double(Model::energy(K_[g], r0, r));
    }
    if (!gone.empty()) remove(bonds, gone);
    return energy;
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
};

}  // namespace basalt::solver
