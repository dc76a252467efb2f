#pragma once
// Loops a rotational bond model (one with `rotational = true`: models/rot_bond.hpp) over the rank's bonds,
// as BondDriver does for central bonds: bonds with both ends owned apply force and moments to both; bonds
// to a ghost to the owned end only. The model is not symmetric in its ends, so every rank evaluates a bond
// with particle 1 = its first end (Bonds::a), from the ghost's exact copy of positions, orientations and
// initial positions: both ranks compute the same loads and break the bond at the same step. The force of
// the step a bond fails in still acts (ESyS tests the criterion on the forces it has just applied); the
// pair is unbonded from the next step. Energies, counts and break records are kept by the rank owning the
// smaller global id. What a bond's law takes from its initial state alone (its springs and strengths
// from the initial length and radii, the initial offset D, the couple shares) is computed once per bond
// and kept until the bond list changes (Bonds::stamp): at a rebuild, a migration or a break.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string_view>
#include <vector>

#include "basalt/solver/interactions/force_compute.hpp"

namespace basalt::solver {

template <class Real, class Model>
class RotBondDriver final : public ForceCompute<Real> {
 public:
  using Coeffs = typename Model::template Coeffs<Real>;

  explicit RotBondDriver(const std::vector<InteractionSpec>& groups) {
    for (const auto& g : groups) {
      params_.push_back(g.template params_of<Model>());
      coeffs_.push_back(Model::template coeffs<Real>(params_.back()));
      breakable_ = breakable_ || Model::breakable(params_.back());
    }
  }

  std::string_view model() const override { return Model::name; }
  ModelKind kind() const override { return ModelKind::bond; }
  Fields reads() const override { return Model::reads; }
  double max_stiffness(double rmax) const override {
    double m = 0;
    for (const auto& p : params_) m = std::max(m, Model::max_stiffness(p, rmax));
    return m;
  }
  bool can_break() const override { return breakable_; }
  std::size_t memory_bytes() const override {
    return fixed_.capacity() * sizeof(BondFixed) + gone_.capacity() * sizeof(std::size_t);
  }
  double rest_length(std::size_t g, double ri, double rj, double r) const override {
    return Model::rest_length(params_[g], ri, rj, r);
  }

  double compute(ForceState<Real>& s, Part part, bool energy, bool) override {
    if (s.bonds.size() == 0) return 0;
    if (stamp_ != s.bonds.stamp || fixed_.size() != s.bonds.size()) refresh(s);
    double e = 0;
    if (part == Part::owned) {
      gone_.clear();
      e = energy ? loop<true, true>(s, 0, s.bonds.n_both_owned)
                 : loop<false, true>(s, 0, s.bonds.n_both_owned);
    } else {
      e = energy ? loop<true, false>(s, s.bonds.n_both_owned, s.bonds.size())
                 : loop<false, false>(s, s.bonds.n_both_owned, s.bonds.size());
      if (!gone_.empty()) {
        // The kept constants of the bonds that stay are still theirs (functions of the initial geometry):
        // dropped in step with the bonds instead of recomputed for all.
        const bool current = stamp_ == s.bonds.stamp;
        s.bonds.erase(gone_);
        if (current) {
          std::size_t kept = 0, g = 0;
          for (std::size_t k = 0; k < fixed_.size(); ++k) {
            if (g < gone_.size() && gone_[g] == k) {
              ++g;
              continue;
            }
            fixed_[kept++] = fixed_[k];
          }
          fixed_.resize(kept);
          stamp_ = s.bonds.stamp;
        }
      }
      gone_.clear();
    }
    return e;
  }

 private:
  static constexpr int kLanes = 8;  ///< bonds evaluated side by side (Model::evaluate_lanes)

  template <bool Energy, bool BothOwned>
  double loop(ForceState<Real>& s, std::size_t begin, std::size_t end) {
    auto& p = s.p;
    const auto& bonds = s.bonds;
    auto& L = lanes_;
    double energy = 0;
    std::size_t n1s[kLanes], n2s[kLanes];
    bool firsts[kLanes];
    for (std::size_t k0 = begin; k0 < end; k0 += kLanes) {
      const int n = static_cast<int>(std::min<std::size_t>(kLanes, end - k0));
      for (int l = 0; l < kLanes; ++l) {  // a short last batch repeats its last bond
        const std::size_t k = k0 + static_cast<std::size_t>(std::min(l, n - 1));
        const auto i = static_cast<std::size_t>(bonds.ia[k]), j = static_cast<std::size_t>(bonds.ib[k]);
        const bool first = p.id[i] == bonds.a[k];
        const std::size_t n1 = first ? i : j, n2 = first ? j : i;
        n1s[l] = n1, n2s[l] = n2, firsts[l] = first;
        const BondFixed& f = fixed_[k];
        L.x1[0][l] = p.x[n1], L.x1[1][l] = p.y[n1], L.x1[2][l] = p.z[n1];
        L.x2[0][l] = p.x[n2], L.x2[1][l] = p.y[n2], L.x2[2][l] = p.z[n2];
        L.q1[0][l] = p.qw[n1], L.q1[1][l] = p.qx[n1], L.q1[2][l] = p.qy[n1], L.q1[3][l] = p.qz[n1];
        L.q2[0][l] = p.qw[n2], L.q2[1][l] = p.qx[n2], L.q2[2][l] = p.qy[n2], L.q2[3][l] = p.qz[n2];
        L.d[0][l] = f.d.x, L.d[1][l] = f.d.y, L.d[2][l] = f.d.z;
        L.r0[l] = bonds.r0[k], L.inv_d[l] = f.f.inv_d, L.e1[l] = f.f.e1, L.e2[l] = f.f.e2;
        L.kn[l] = f.k.kn, L.ks[l] = f.k.ks, L.kb[l] = f.k.kb, L.kt[l] = f.k.kt;
      }
      Model::evaluate_lanes(L);
      for (int l = 0; l < n; ++l) {
        const std::size_t k = k0 + static_cast<std::size_t>(l);
        const std::size_t n1 = n1s[l], n2 = n2s[l];
        const bool first = firsts[l];
        const BondFixed& f = fixed_[k];
        const auto& bk = f.k;
        typename Model::template Geometry<Real> g;
        g.x1 = {L.x1[0][l], L.x1[1][l], L.x1[2][l]};
        g.x2 = {L.x2[0][l], L.x2[1][l], L.x2[2][l]};
        g.r0 = L.r0[l];
        typename Model::template Result<Real> q;
        if (L.general[l] != Real(0) || bk.atan2_angles) [[unlikely]] {
          g.q1 = {L.q1[0][l], L.q1[1][l], L.q1[2][l], L.q1[3][l]};
          g.q2 = {L.q2[0][l], L.q2[1][l], L.q2[2][l], L.q2[3][l]};
          g.d = f.d;
          q = Model::evaluate(bk, g, f.f);
        } else {
          q.f1 = {L.f1[0][l], L.f1[1][l], L.f1[2][l]};
          q.m1 = {L.m1[0][l], L.m1[1][l], L.m1[2][l]};
          q.m2 = {L.m2[0][l], L.m2[1][l], L.m2[2][l]};
          q.fn = L.fn[l], q.fs = L.fs[l], q.mb = L.mb[l], q.mt = L.mt[l];
        }
        const bool own1 = BothOwned || first, own2 = BothOwned || !first;
        if (own1) {
          p.fx[n1] += q.f1.x, p.fy[n1] += q.f1.y, p.fz[n1] += q.f1.z;
          p.tx[n1] += q.m1.x, p.ty[n1] += q.m1.y, p.tz[n1] += q.m1.z;
        }
        if (own2) {
          p.fx[n2] -= q.f1.x, p.fy[n2] -= q.f1.y, p.fz[n2] -= q.f1.z;
          p.tx[n2] += q.m2.x, p.ty[n2] += q.m2.y, p.tz[n2] += q.m2.z;
        }
        const std::size_t i = first ? n1 : n2, j = first ? n2 : n1;
        const bool tally = BothOwned || p.id[i] < p.id[j];
        if constexpr (Energy)
          if (tally) energy += Model::energy(bk, q);
        if (!breakable_) continue;
        const int mode = Model::failure(coeffs_[bonds.group_of(k)], bk, q);
        if (mode < 0) [[likely]]
          continue;
        gone_.push_back(k);
        if (p.with_damage) {  // each rank counts the break for its own particles
          ++p.bonds_broken[i];
          if constexpr (BothOwned) ++p.bonds_broken[j];
        }
        if (tally) {
          const double w = double(p.radius[n2]) / double(p.radius[n1] + p.radius[n2]);
          const auto d = g.x1 - g.x2;
          s.broken.push_back({bonds.a[k], bonds.b[k], double(d.norm()), double(g.r0), -1, bonds.group_of(k),
                              static_cast<std::uint8_t>(mode), double(g.x2.x) + w * double(d.x),
                              double(g.x2.y) + w * double(d.y), double(g.x2.z) + w * double(d.z)});
        }
      }
    }
    return energy;
  }

  /// Each bond's constants, in the bond list's order.
  struct BondFixed {
    typename Model::template BondCoeffs<Real> k;
    typename Model::template Fixed<Real> f;
    decltype(Model::template Geometry<Real>::d) d;  ///< x2 - x1 at the start
  };

  void refresh(const ForceState<Real>& s) {
    const auto& p = s.p;
    const auto& bonds = s.bonds;
    fixed_.resize(bonds.size());
    for (std::size_t k = 0; k < bonds.size(); ++k) {
      const auto i = static_cast<std::size_t>(bonds.ia[k]), j = static_cast<std::size_t>(bonds.ib[k]);
      const bool first = p.id[i] == bonds.a[k];
      const std::size_t n1 = first ? i : j, n2 = first ? j : i;
      typename Model::template Geometry<Real> g;
      g.d = {p.xi[n2] - p.xi[n1], p.yi[n2] - p.yi[n1], p.zi[n2] - p.zi[n1]};
      g.r1 = p.radius[n1];
      g.r2 = p.radius[n2];
      fixed_[k] = {Model::bond_coeffs(coeffs_[bonds.group_of(k)], g.d.norm(), g.r1, g.r2), Model::fixed(g),
                   g.d};
    }
    stamp_ = bonds.stamp;
  }

  std::vector<typename Model::Params> params_;
  std::vector<Coeffs> coeffs_;
  bool breakable_ = false;
  std::vector<std::size_t> gone_;
  std::vector<BondFixed> fixed_;
  typename Model::template Lanes<Real, kLanes> lanes_;
  std::uint64_t stamp_ = 0;
};

}  // namespace basalt::solver
