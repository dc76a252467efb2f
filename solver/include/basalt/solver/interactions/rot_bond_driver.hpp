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

#include "basalt/solver/interactions/driver_base.hpp"

namespace basalt::solver {

template <class Real, class Model>
class RotBondDriver final : public ModelDriver<Real, Model> {
  using Base = ModelDriver<Real, Model>;

 public:
  using Coeffs = typename Base::Coeffs;

  explicit RotBondDriver(const std::vector<InteractionSpec>& groups) {
    for (const auto& g : groups) {
      this->add_group(g.template params_of<Model>());
      breakable_ = breakable_ || Model::breakable(params_.back());
    }
    atan2_lanes_ = !params_.empty() &&
                   std::all_of(params_.begin(), params_.end(), [](const auto& p) { return p.atan2_angles; });
  }

  bool can_break() const override { return breakable_; }
  std::size_t memory_bytes() const override {
    return table_.bytes() + gone_.capacity() * sizeof(std::size_t);
  }
  double rest_length(std::size_t g, double ri, double rj, double r) const override {
    return Model::rest_length(params_[g], ri, rj, r);
  }

  double compute(ForceState<Real>& s, Part part, bool energy, bool) override {
    if (s.bonds.size() == 0) return 0;
    if (stamp_ != s.bonds.stamp || n_ != s.bonds.size()) refresh(s);
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
          pad(table_.erase(gone_, n_));
          stamp_ = s.bonds.stamp;
        }
      }
      gone_.clear();
    }
    return e;
  }

 private:
  static constexpr int kLanes = 16;  ///< bonds evaluated side by side (Model::evaluate_lanes)

  template <bool Energy, bool BothOwned>
  double loop(ForceState<Real>& s, std::size_t begin, std::size_t end) {
    auto& p = s.p;
    const auto& bonds = s.bonds;
    const auto& t = table_;
    auto& L = lanes_;
    L.x = p.x.data(), L.y = p.y.data(), L.z = p.z.data();
    L.qw = p.qw.data(), L.qx = p.qx.data(), L.qy = p.qy.data(), L.qz = p.qz.data();
    L.table = &table_;
    double energy = 0;
    for (std::size_t k0 = begin; k0 < end; k0 += kLanes) {
      const int n = static_cast<int>(std::min<std::size_t>(kLanes, end - k0));
      L.k0 = k0;  // a short last batch reads the next bonds or the table's padding
      if (atan2_lanes_)
        Model::template evaluate_lanes<Real, kLanes, true>(L);
      else
        Model::template evaluate_lanes<Real, kLanes, false>(L);
      for (int l = 0; l < n; ++l) {
        const std::size_t k = k0 + static_cast<std::size_t>(l);
        const std::size_t n1 = t.n1[k], n2 = t.n2[k];
        typename Model::template Result<Real> q;
        const bool general = L.general[l] != Real(0);
        if (general) [[unlikely]] {
          typename Model::template Geometry<Real> g;
          g.x1 = {p.x[n1], p.y[n1], p.z[n1]};
          g.x2 = {p.x[n2], p.y[n2], p.z[n2]};
          g.q1 = {p.qw[n1], p.qx[n1], p.qy[n1], p.qz[n1]};
          g.q2 = {p.qw[n2], p.qx[n2], p.qy[n2], p.qz[n2]};
          g.d = t.d(k);
          g.r0 = bonds.r0[k];
          q = Model::evaluate(t.coeffs(k), g, t.fixed(k));
        } else {
          q.f1 = {L.f1[0][l], L.f1[1][l], L.f1[2][l]};
          q.m1 = {L.m1[0][l], L.m1[1][l], L.m1[2][l]};
          q.m2 = {L.m2[0][l], L.m2[1][l], L.m2[2][l]};
          q.fn = L.fn[l], q.fs = L.fs[l], q.mb = L.mb[l], q.mt = L.mt[l];
        }
        // ia, the owned end (Bonds), is n1 or n2.
        const bool own1 = BothOwned || n1 < p.n_owned, own2 = BothOwned || !own1;
        if (own1) {
          p.fx[n1] += q.f1.x, p.fy[n1] += q.f1.y, p.fz[n1] += q.f1.z;
          p.tx[n1] += q.m1.x, p.ty[n1] += q.m1.y, p.tz[n1] += q.m1.z;
        }
        if (own2) {
          p.fx[n2] -= q.f1.x, p.fy[n2] -= q.f1.y, p.fz[n2] -= q.f1.z;
          p.tx[n2] += q.m2.x, p.ty[n2] += q.m2.y, p.tz[n2] += q.m2.z;
        }
        const std::size_t i = own1 ? n1 : n2, j = own1 ? n2 : n1;
        const bool tally = BothOwned || p.id[i] < p.id[j];
        if constexpr (Energy)
          if (tally) energy += Model::energy(t.coeffs(k), q);
        if (!breakable_ || (!general && L.broken[l] == Real(0))) [[likely]]
          continue;
        const auto& c = coeffs_[bonds.group_of(k)];
        const int mode = general ? Model::failure(c, t.coeffs(k), q) : Model::failure_mode(c, t.coeffs(k), q);
        if (mode < 0) continue;
        gone_.push_back(k);
        if (p.with_damage) {  // each rank counts the break for its own particles
          ++p.bonds_broken[i];
          if constexpr (BothOwned) ++p.bonds_broken[j];
        }
        if (tally) {
          typename Model::template Geometry<Real> g;
          g.x1 = {p.x[n1], p.y[n1], p.z[n1]};
          g.x2 = {p.x[n2], p.y[n2], p.z[n2]};
          s.broken.push_back(broken_bond<Real>(bonds.a[k], bonds.b[k], double((g.x1 - g.x2).norm()),
                                               double(bonds.r0[k]), bonds.group_of(k),
                                               static_cast<std::uint8_t>(mode), {p.x[n2], p.y[n2], p.z[n2]},
                                               p.radius[n2], {p.x[n1], p.y[n1], p.z[n1]}, p.radius[n1]));
        }
      }
    }
    return energy;
  }

  /// The bond table for the bond list: n1 is the bond's first end (Bonds::a), as every rank evaluates it.
  void refresh(const ForceState<Real>& s) {
    const auto& p = s.p;
    const auto& bonds = s.bonds;
    n_ = bonds.size();
    table_.one_group = coeffs_.size() == 1;
    table_.resize(n_ + kLanes);
    for (std::size_t k = 0; k < n_; ++k) {
      const auto i = static_cast<std::uint32_t>(bonds.ia[k]), j = static_cast<std::uint32_t>(bonds.ib[k]);
      const bool first = p.id[i] == bonds.a[k];
      const std::uint32_t n1 = first ? i : j, n2 = first ? j : i;
      typename Model::template Geometry<Real> g;
      g.d = {p.xi[n2] - p.xi[n1], p.yi[n2] - p.yi[n1], p.zi[n2] - p.zi[n1]};
      g.r1 = p.radius[n1];
      g.r2 = p.radius[n2];
      const auto& c = coeffs_[bonds.group_of(k)];
      table_.set(k, n1, n2, c, Model::bond_coeffs(c, g.d.norm(), g.r1, g.r2), Model::fixed(g), g.d,
                 bonds.r0[k]);
    }
    pad(n_);
    stamp_ = bonds.stamp;
  }

  /// Keeps the first n bonds and fills the batch after them with copies of the last (read, not applied).
  void pad(std::size_t n) {
    n_ = n;
    table_.resize(n + kLanes);
    for (std::size_t k = n; k < n + kLanes; ++k) table_.copy(k, n > 0 ? n - 1 : k);
  }

  using Base::params_, Base::coeffs_;
  bool breakable_ = false;
  bool atan2_lanes_ =
      false;  ///< every group takes atan2 angles: the lanes evaluate them (else the acos ones)
  std::vector<std::size_t> gone_;
  typename Model::template Table<Real> table_;  ///< each bond's constants, padded by a batch
  std::size_t n_ = 0;                           ///< bonds in table_
  typename Model::template Lanes<Real, kLanes> lanes_{};
  std::uint64_t stamp_ = 0;
};

}  // namespace basalt::solver
