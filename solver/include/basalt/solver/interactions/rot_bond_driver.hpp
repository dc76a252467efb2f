#pragma once
// Loops a rotational bond model (one with `rotational = true`: models/rot_bond.hpp) over the rank's bonds,
// as BondDriver does for central bonds: bonds with both ends owned apply force and moments to both; bonds
// to a ghost to the owned end only. The model is not symmetric in its ends, so every rank evaluates a bond
// with particle 1 = its first end (Bonds::a), from the ghost's exact copy of positions, orientations and
// initial positions: both ranks compute the same loads and break the bond at the same step. The force of
// the step a bond fails in still acts (ESyS tests the criterion on the forces it has just applied); the
// pair is unbonded from the next step. Energies, counts and break records are kept by the rank owning the
// smaller global id.
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
  double rest_length(std::size_t g, double ri, double rj, double r) const override {
    return Model::rest_length(params_[g], ri, rj, r);
  }

  double compute(ForceState<Real>& s, Part part, bool energy, bool) override {
    if (s.bonds.size() == 0) return 0;
    double e = 0;
    if (part == Part::owned) {
      gone_.clear();
      e = energy ? loop<true, true>(s, 0, s.bonds.n_both_owned)
                 : loop<false, true>(s, 0, s.bonds.n_both_owned);
    } else {
      e = energy ? loop<true, false>(s, s.bonds.n_both_owned, s.bonds.size())
                 : loop<false, false>(s, s.bonds.n_both_owned, s.bonds.size());
      if (!gone_.empty()) s.bonds.erase(gone_);
      gone_.clear();
    }
    return e;
  }

 private:
  template <bool Energy, bool BothOwned>
  double loop(ForceState<Real>& s, std::size_t begin, std::size_t end) {
    auto& p = s.p;
    const auto& bonds = s.bonds;
    double energy = 0;
    for (std::size_t k = begin; k < end; ++k) {
      const auto i = static_cast<std::size_t>(bonds.ia[k]), j = static_cast<std::size_t>(bonds.ib[k]);
      const bool first = p.id[i] == bonds.a[k];
      const std::size_t n1 = first ? i : j, n2 = first ? j : i;
      const Coeffs& c = coeffs_[bonds.group_of(k)];
      typename Model::template Geometry<Real> g;
      g.x1 = {p.x[n1], p.y[n1], p.z[n1]};
      g.x2 = {p.x[n2], p.y[n2], p.z[n2]};
      g.q1 = {p.qw[n1], p.qx[n1], p.qy[n1], p.qz[n1]};
      g.q2 = {p.qw[n2], p.qx[n2], p.qy[n2], p.qz[n2]};
      g.d = {p.xi[n2] - p.xi[n1], p.yi[n2] - p.yi[n1], p.zi[n2] - p.zi[n1]};
      g.r1 = p.radius[n1];
      g.r2 = p.radius[n2];
      g.r0 = bonds.r0[k];
      const auto bk = Model::bond_coeffs(c, g.d.norm(), g.r1, g.r2);
      const auto q = Model::evaluate(bk, g);
      const bool own1 = BothOwned || first, own2 = BothOwned || !first;
      if (own1) {
        p.fx[n1] += q.f1.x, p.fy[n1] += q.f1.y, p.fz[n1] += q.f1.z;
        p.tx[n1] += q.m1.x, p.ty[n1] += q.m1.y, p.tz[n1] += q.m1.z;
      }
      if (own2) {
        p.fx[n2] -= q.f1.x, p.fy[n2] -= q.f1.y, p.fz[n2] -= q.f1.z;
        p.tx[n2] += q.m2.x, p.ty[n2] += q.m2.y, p.tz[n2] += q.m2.z;
      }
      const bool tally = BothOwned || p.id[i] < p.id[j];
      if constexpr (Energy)
        if (tally) energy += Model::energy(bk, q);
      if (!breakable_) continue;
      const int mode = Model::failure(c, bk, q);
      if (mode < 0) [[likely]]
        continue;
      gone_.push_back(k);
      if (p.with_damage) {  // each rank counts the break for its own particles
        ++p.bonds_broken[i];
        if constexpr (BothOwned) ++p.bonds_broken[j];
      }
      if (tally) {
        const double w = double(g.r2) / double(g.r1 + g.r2);  // contact point: r1 from 1 towards 2
        const auto d = g.x1 - g.x2;
        s.broken.push_back({bonds.a[k], bonds.b[k], double(d.norm()), double(g.r0), -1, bonds.group_of(k),
                            static_cast<std::uint8_t>(mode), double(g.x2.x) + w * double(d.x),
                            double(g.x2.y) + w * double(d.y), double(g.x2.z) + w * double(d.z)});
      }
    }
    return energy;
  }

  std::vector<typename Model::Params> params_;
  std::vector<Coeffs> coeffs_;
  bool breakable_ = false;
  std::vector<std::size_t> gone_;
};

}  // namespace basalt::solver
