#pragma once
// Loops the bonded wall model (models/bonded_wall.hpp) over the walls that use it: each wall's
// candidates (Walls::rebuild) are the owned particles of its bond_tags, wherever they are, plus the
// particles its tags let touch it within radius + skin. A bond's rest offset x(0) - p_w(0) is its
// history: taken when the driver first meets the particle (the run's first rebuild, at t = 0), then
// carried by id like any wall contact's history (across rebuilds, with migrating particles, in
// checkpoints as a contact whose second id is -1 - wall index). Tallies the force on each wall and the
// springs' energy (ledger term wall_potential_energy).
#include <cstring>
#include <string_view>
#include <vector>

#include "basalt/solver/interactions/driver_base.hpp"
#include "basalt/solver/interactions/history_records.hpp"
#include "basalt/solver/models/bonded_wall.hpp"

namespace basalt::solver {

template <class Real, class Model = BondedWall>
class BondedWallDriver final : public ContactDriver<Real, Model, BondedWallDriver<Real, Model>> {
  using Base = ContactDriver<Real, Model, BondedWallDriver<Real, Model>>;

 public:
  using Coeffs = typename Base::Coeffs;
  using History = typename Base::History;
  static_assert(Base::kHistory);

  explicit BondedWallDriver(const std::vector<WallSpec>& walls) {
    for (std::size_t w = 0; w < walls.size(); ++w) {
      if (walls[w].model != Model::name) continue;
      index_.push_back(w);
      this->add_group(walls[w].template params_of<Model>());
    }
    hist_.resize(index_.size());
  }

  double compute(ForceState<Real>& s, Part part, bool energy, bool /*advance*/) override {
    if (part != Part::owned) return 0;
    return energy ? loop<true>(s.p, s.walls) : loop<false>(s.p, s.walls);
  }

  void rebuild_walls(const Particles<Real>& p, const Walls& walls) override {
    walls_ = &walls;
    const ContactLookup records(pending_);
    for (std::size_t k = 0; k < index_.size(); ++k) {
      const std::size_t w = index_[k];
      const auto& spec = walls.spec(w);
      const auto& at = walls.point(w);
      const auto& cand = walls.candidates(w);
      auto& h = hist_[k];
      // (a record is saved only for a bond, bonded = 1: a history holds something exactly when bonded)
      restore_candidates(p, cand, pending_, records, wall_id(k), h);
      for (std::size_t c = 0; c < cand.size(); ++c) {
        const auto i = static_cast<std::size_t>(cand[c]);
        if (!holds(h[c]) && spec.bonds(p.tag[i]))  // first met: the rest offset is where it is now
          h[c] = {double(p.x[i]) - at[0], double(p.y[i]) - at[1], double(p.z[i]) - at[2], 1.0};
      }
    }
    pending_.clear();
  }
  /// The records of the bonds (ContactDriver: save_history, history_records).
  void collect(const Particles<Real>& p, ContactRecords& out) const {
    out.width = history_width<Model>();
    if (!walls_) return;
    for (std::size_t k = 0; k < index_.size(); ++k)
      collect_candidates(p, walls_->candidates(index_[k]), hist_[k], wall_id(k), out);
  }
  std::size_t memory_bytes() const override {
    std::size_t b = 0;
    for (const auto& h : hist_) b += h.capacity() * sizeof(History);
    return b;
  }

 private:
  std::int64_t wall_id(std::size_t k) const { return wall_record_id(index_[k]); }

  template <bool Energy>
  double loop(Particles<Real>& p, Walls& walls) {
    walls_ = &walls;
    double energy = 0;
    for (std::size_t k = 0; k < index_.size(); ++k) {
      const std::size_t w = index_[k];
      const auto& spec = walls.spec(w);
      const auto& c = coeffs_[k];
      const Real nx = Real(spec.normal[0]), ny = Real(spec.normal[1]), nz = Real(spec.normal[2]);
      const auto& at = walls.point(w);
      const Real px = Real(at[0]), py = Real(at[1]), pz = Real(at[2]);
      const auto& cand = walls.candidates(w);
      const auto& hist = hist_[k];
      double wfx = 0, wfy = 0, wfz = 0;
      for (std::size_t ci = 0; ci < cand.size(); ++ci) {
        const auto i = static_cast<std::size_t>(cand[ci]);
        const History& h = hist[ci];
        Real fx, fy, fz;
        if (h.bonded != 0) {  // F = -k ((x - p_w) - d0)
          const Real kb = Model::bond_stiffness(c, p.radius[i]);
          const Real ex = (p.x[i] - px) - Real(h.d0x), ey = (p.y[i] - py) - Real(h.d0y),
                     ez = (p.z[i] - pz) - Real(h.d0z);
          fx = -kb * ex, fy = -kb * ey, fz = -kb * ez;
          if constexpr (Energy) energy += 0.5 * double(kb) * double(ex * ex + ey * ey + ez * ez);
        } else {  // the elastic wall
          const Real d = (p.x[i] - px) * nx + (p.y[i] - py) * ny + (p.z[i] - pz) * nz;
          const Real o = p.radius[i] - d;
          if (o <= 0) continue;
          const Real ke = Model::elastic_stiffness(c, p.radius[i]);
          fx = ke * o * nx, fy = ke * o * ny, fz = ke * o * nz;
          if constexpr (Energy) energy += 0.5 * double(ke) * double(o * o);
        }
        p.fx[i] += fx;
        p.fy[i] += fy;
        p.fz[i] += fz;
        wfx -= double(fx);
        wfy -= double(fy);
        wfz -= double(fz);
      }
      walls.force(w) = {wfx, wfy, wfz};
    }
    return energy;
  }

  using Base::coeffs_, Base::pending_;
  std::vector<std::size_t> index_;
  std::vector<std::vector<History>> hist_;  ///< per wall of this model, per candidate
  const Walls* walls_ = nullptr;
};

}  // namespace basalt::solver
