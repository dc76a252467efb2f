#pragma once
// Loops a bond model over the rank's bonds. Bonds with both ends owned apply Newton's third law once;
// bonds to a ghost apply the force to the owned end only (the ghost's owner computes the same bond
// from identical positions, so both ranks also agree when it breaks). Energies and counts are tallied
// by the rank owning the smaller global id, so sums over ranks count each bond once. A bond's rest
// length is its history, kept by the bond store (Bonds::r0).
#include <cmath>
#include <cstdint>
#include <string_view>
#include <vector>

#include "basalt/solver/interactions/driver_base.hpp"

namespace basalt::solver {

template <class Real, class Model>
class BondDriver final : public ModelDriver<Real, Model> {
  using Base = ModelDriver<Real, Model>;

 public:
  using Coeffs = typename Base::Coeffs;

  /// Takes the scene's bond groups (all of model Model: Bonds::group indexes them).
  explicit BondDriver(const std::vector<InteractionSpec>& groups) {
    for (const auto& g : groups) {
      this->add_group(g.template params_of<Model>());
      breakable_ = breakable_ || Model::breakable(params_.back());
    }
  }

  bool can_break() const override { return breakable_; }
  double rest_length(std::size_t g, double ri, double rj, double r) const override {
    return Model::rest_length(params_[g], ri, rj, r);
  }

  /// The owned part (bonds with both ends owned) comes first; the ghost part ends the step's bond
  /// work and removes the bonds that broke in either part.
  double compute(ForceState<Real>& s, Part part, bool energy, bool) override {
    if (s.bonds.size() == 0) return 0;
    double e = 0;
    if (part == Part::owned) {
      gone_.clear();
      e = energy ? dispatch<true, true>(s) : dispatch<false, true>(s);
    } else {
      e = energy ? dispatch<true, false>(s) : dispatch<false, false>(s);
      if (!gone_.empty()) s.bonds.erase(gone_);
      gone_.clear();
    }
    return e;
  }

 private:
  template <bool Energy, bool BothOwned>
  double dispatch(ForceState<Real>& s) {
    const std::size_t b = BothOwned ? 0 : s.bonds.n_both_owned,
                      e = BothOwned ? s.bonds.n_both_owned : s.bonds.size();
    if (coeffs_.size() == 1 && !breakable_) return loop<Energy, true, false, BothOwned>(s, b, e);
    if (coeffs_.size() == 1) return loop<Energy, true, true, BothOwned>(s, b, e);
    return loop<Energy, false, true, BothOwned>(s, b, e);
  }

  template <bool Energy, bool Uniform, bool Breakable, bool BothOwned>
  double loop(ForceState<Real>& s, std::size_t begin, std::size_t end) {
    auto& p = s.p;
    const auto& bonds = s.bonds;
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
    const Coeffs c0 = coeffs_[0];
    for (std::size_t k = begin; k < end; ++k) {
      const auto i = static_cast<std::size_t>(ia[k]), j = static_cast<std::size_t>(ib[k]);
      const Real dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
      const Real r = std::sqrt(dx * dx + dy * dy + dz * dz);
      const Real r0 = r0s[k];
      const Coeffs& c = Uniform ? c0 : coeffs_[bonds.group[k]];
      bool gone = false;
      if constexpr (Breakable) {
        if (Model::broken(c, r0, r)) [[unlikely]] {
          gone_.push_back(k);
          if (p.with_damage) {  // each rank counts the break for its own particles
            ++p.bonds_broken[i];
            if constexpr (BothOwned) ++p.bonds_broken[j];
          }
          if (BothOwned || p.id[i] < p.id[j])  // a tension failure
            s.broken.push_back(broken_bond<Real>(bonds.a[k], bonds.b[k], double(r), double(r0),
                                                 bonds.group_of(k), 0, {x[i], y[i], z[i]}, p.radius[i],
                                                 {x[j], y[j], z[j]}, p.radius[j]));
          if (!pulls_when_broken(c)) continue;
          gone = true;  // (its energy is the break's loss, not the network's)
        }
      }
      const Real f = Model::force(c, r0, r) / r;
      fx[i] += f * dx;
      fy[i] += f * dy;
      fz[i] += f * dz;
      if constexpr (BothOwned) {
        fx[j] -= f * dx;
        fy[j] -= f * dy;
        fz[j] -= f * dz;
      }
      if constexpr (Energy)
        if (!gone && (BothOwned || p.id[i] < p.id[j])) energy += double(Model::energy(c, r0, r));
    }
    return energy;
  }

  /// A model may have the forces that find a bond broken still take its pull (LinearBond's ESyS convention).
  static bool pulls_when_broken(const Coeffs& c) {
    if constexpr (requires { Model::pulls_when_broken(c); })
      return Model::pulls_when_broken(c);
    else
      return false;
  }

  using Base::params_, Base::coeffs_;
  bool breakable_ = false;
  std::vector<std::size_t> gone_;
};

}  // namespace basalt::solver
