#pragma once
// Loops a wall model over the walls of the scene that use it and the owned particles within reach of
// each (Walls::candidates). Tallies the force on each wall (minus the sum of forces it puts on
// particles) and the wall energy; walls act on owned particles only, so there is no ghost part.
// A velocity-dependent model (friction) gets the contact's kinematics and keeps a History per
// (wall, particle) beside the candidates: saved by (particle id, -1 - wall index) before a rebuild,
// carried with a migrating particle, found again by those ids, and written to checkpoints as a
// contact whose second id is -1 - wall index (docs/formats.md).
#include <array>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <type_traits>
#include <vector>

#include "basalt/solver/interactions/driver_base.hpp"
#include "basalt/solver/interactions/history_records.hpp"
#include "basalt/solver/interactions/lane_pass.hpp"
#include "basalt/solver/models/lanes.hpp"

namespace basalt::solver {

template <class Real, class Model>
class WallDriver final : public ContactDriver<Real, Model, WallDriver<Real, Model>> {
  using Base = ContactDriver<Real, Model, WallDriver<Real, Model>>;

 public:
  using Coeffs = typename Base::Coeffs;
  using History = typename Base::History;
  static constexpr bool kKinematic = (Model::reads & kVelocity) != 0;
  using Base::kHistory;
  static constexpr int kLaneWidth = kContactLaneWidth;
  using Lanes = WallLanes<Real, kLaneWidth, History>;
  /// The model evaluates contacts side by side (Model::contact_lanes, model.hpp WallLanes).
  static constexpr bool kLanes = requires(const Coeffs& c, Lanes& b) {
    Model::template contact_lanes<true>(c, b);
  };

  /// Takes the scene's walls whose model is Model.
  explicit WallDriver(const std::vector<WallSpec>& walls) {
    for (std::size_t w = 0; w < walls.size(); ++w) {
      if (walls[w].model != Model::name) continue;
      index_.push_back(w);
      this->add_group(walls[w].template params_of<Model>());
    }
    hist_.resize(index_.size());
  }

  double compute(ForceState<Real>& s, Part part, bool energy, bool advance) override {
    if (part != Part::owned) return 0;
    this->start_step(part, advance);
    if constexpr (kKinematic) {
      if (advance)
        return energy ? loop_kinematic<true, true>(s.p, s.walls) : loop_kinematic<false, true>(s.p, s.walls);
      return energy ? loop_kinematic<true, false>(s.p, s.walls) : loop_kinematic<false, false>(s.p, s.walls);
    } else {
      return energy ? loop<true>(s.p, s.walls) : loop<false>(s.p, s.walls);
    }
  }

  // History (kinematic models with a History only).
  void rebuild_walls(const Particles<Real>& p, const Walls& walls) override {
    walls_ = &walls;
    if constexpr (kHistory) {
      const ContactLookup records(pending_);
      for (std::size_t k = 0; k < index_.size(); ++k)
        restore_candidates(p, walls.candidates(index_[k]), pending_, records, wall_id(k), hist_[k]);
      pending_.clear();
    }
  }
  /// The records of the walls' contacts (ContactDriver: save_history, history_records).
  void collect(const Particles<Real>& p, ContactRecords& out) const {
    out.width = history_width<Model>();
    if (!walls_) return;
    for (std::size_t k = 0; k < index_.size(); ++k)
      collect_candidates(p, walls_->candidates(index_[k]), hist_[k], wall_id(k), out);
  }
  /// The model has a closed-form collision (Model::collision, stability/impact.hpp).
  static constexpr bool kCollides = requires(const typename Base::Params& q) {
    { Model::collision(q, 1.0, 1.0, 1.0, 0.0) } -> std::same_as<Collision>;
  };
  bool sees_impacts() const override { return kCollides; }
  /// Each wall's candidates touching it or moving towards it (relative to the wall): the collision of fewest
  /// steps, and the counts of collisions whose overlap passes 5 % and 20 % of the radius.
  CollisionSeen shortest_collision(const Particles<Real>& p, const Walls& walls, double dt,
                                   const std::vector<std::int64_t>& fixed) const override {
    CollisionSeen worst;
    if constexpr (kCollides) {
      for (std::size_t k = 0; k < index_.size(); ++k) {
        const std::size_t w = index_[k];
        const auto& n = walls.spec(w).normal;
        const auto& at = walls.point(w);
        const auto& vw = walls.velocity(w);
        for (const auto ci : walls.candidates(w)) {
          const auto i = static_cast<std::size_t>(ci);
          const double r = double(p.radius[i]);
          const double s = (double(p.x[i]) - at[0]) * n[0] + (double(p.y[i]) - at[1]) * n[1] +
                           (double(p.z[i]) - at[2]) * n[2];
          const double un = (double(p.vx[i]) - vw[0]) * n[0] + (double(p.vy[i]) - vw[1]) * n[1] +
                            (double(p.vz[i]) - vw[2]) * n[2];
          if ((!(s < r) && !(un < 0)) || fixed_tag(fixed, p.tag[i])) continue;  // apart and not coming closer
          const Collision c =
              Model::collision(this->params_[k], r, 1 / double(p.inv_mass[i]), -un, s < r ? r - s : 0.0);
          if (!(c.duration > 0)) continue;
          worst.count(c.overlap, r);
          if (!(c.duration / dt < worst.steps)) continue;
          worst.set(c, dt, r, 0.0, p.id[i], -1, int(w));
        }
      }
    }
    return worst;
  }
  std::size_t memory_bytes() const override {
    std::size_t b = 0;
    for (const auto& h : hist_) b += h.capacity() * sizeof(History);
    return b;
  }

 private:
  /// The second id of a wall contact's record: -1 - the wall's index in the scene.
  std::int64_t wall_id(std::size_t k) const { return wall_record_id(index_[k]); }

  /// Wall w's unit normal, point and velocity in the loops' precision.
  struct Plane {
    Real nx, ny, nz, px, py, pz, vx, vy, vz;
  };
  static Plane plane(const Walls& walls, std::size_t w) {
    const auto& n = walls.spec(w).normal;
    const auto& at = walls.point(w);
    const auto& v = walls.velocity(w);
    return {Real(n[0]),  Real(n[1]), Real(n[2]), Real(at[0]), Real(at[1]),
            Real(at[2]), Real(v[0]), Real(v[1]), Real(v[2])};
  }
  /// The histories of the k-th wall's n candidates (cleared when the candidates changed without a rebuild).
  History* histories(std::size_t k, std::size_t n) {
    auto& h = hist_[k];
    if (h.size() != n) h.assign(n, History{});
    return h.data();
  }

  template <bool Energy>
  double loop(Particles<Real>& p, Walls& walls) const {
    double energy = 0;
    for (std::size_t k = 0; k < index_.size(); ++k) {
      const std::size_t w = index_[k];
      const auto& c = coeffs_[k];
      const auto [nx, ny, nz, px, py, pz, vwx, vwy, vwz] = plane(walls, w);
      double wfx = 0, wfy = 0, wfz = 0;
      for (const auto i : walls.candidates(w)) {
        const Real d = (p.x[i] - px) * nx + (p.y[i] - py) * ny + (p.z[i] - pz) * nz;
        const Real o = p.radius[i] - d;
        if (o <= 0) continue;
        const Real f = Model::force(c, p.radius[i], o);
        p.fx[i] += f * nx;
        p.fy[i] += f * ny;
        p.fz[i] += f * nz;
        wfx -= double(f * nx);
        wfy -= double(f * ny);
        wfz -= double(f * nz);
        if constexpr (Energy) energy += double(Model::energy(c, p.radius[i], o));
      }
      walls.force(w) = {wfx, wfy, wfz};
    }
    return energy;
  }

  template <bool Energy, bool Advance>
  double loop_kinematic(Particles<Real>& p, Walls& walls) {
    if constexpr (kLanes)
      return p.with_rotation ? lanes<Energy, Advance, true>(p, walls)
                             : lanes<Energy, Advance, false>(p, walls);
    else
      return p.with_rotation ? loop_kinematic<Energy, Advance, true>(p, walls)
                             : loop_kinematic<Energy, Advance, false>(p, walls);
  }

  /// loop_kinematic() for a model with contact_lanes: each wall's candidates in candidate order through the
  /// lane pass (lane_pass.hpp), their particle data asked for kAhead candidates ahead, their forces added in
  /// that order.
  template <bool Energy, bool Advance, bool Rot>
  double lanes(Particles<Real>& p, Walls& walls) {
    walls_ = &walls;
    const Real* __restrict x = p.x.data();
    const Real* __restrict y = p.y.data();
    const Real* __restrict z = p.z.data();
    const Real* __restrict rad = p.radius.data();
    Real* __restrict fx = p.fx.data();
    Real* __restrict fy = p.fy.data();
    Real* __restrict fz = p.fz.data();
    [[maybe_unused]] Real* __restrict tx = Rot ? p.tx.data() : nullptr;
    [[maybe_unused]] Real* __restrict ty = Rot ? p.ty.data() : nullptr;
    [[maybe_unused]] Real* __restrict tz = Rot ? p.tz.data() : nullptr;
    auto& L = lanes_;
    L.dt = dt_;
    alignas(64) std::uint32_t lane_i[kLaneWidth];
    const auto ahead = lane_arrays<Rot>(p);
    LaneTally t;  // (over all walls: the sums run on from wall to wall)
    for (std::size_t k = 0; k < index_.size(); ++k) {
      const std::size_t w = index_[k];
      const auto c = coeffs_[k];
      const auto [nx, ny, nz, px, py, pz, vwx, vwy, vwz] = plane(walls, w);
      L.nx = nx, L.ny = ny, L.nz = nz;
      double wfx = 0, wfy = 0, wfz = 0;
      const auto& cand = walls.candidates(w);
      const auto* __restrict ci_of = cand.data();
      const std::size_t nc = cand.size();
      // The contacts are found with positions and radii alone; the lanes see the distance that found them.
      const auto find = [&](const std::uint32_t ci, const int l) {
        if (ci + kAhead < nc) {
          const auto a = static_cast<std::size_t>(ci_of[ci + kAhead]);
          for (const Real* f : ahead) __builtin_prefetch(f + a);
        }
        const auto i = static_cast<std::uint32_t>(ci_of[ci]);
        const Real d = (x[i] - px) * nx + (y[i] - py) * ny + (z[i] - pz) * nz;
        lane_i[l] = i, L.d[l] = d;
        return LaneFound{d < rad[i], true};
      };
      const auto load = [&](const int filled) {
        Pass::pad(lane_i, filled), Pass::pad(L.d, filled);
        gather<Rot>(p, lane_i, vwx, vwy, vwz, L);
      };
      const auto add = [&](const int l) {
        const std::size_t i = lane_i[l];
        const Real gx = L.fx[l], gy = L.fy[l], gz = L.fz[l];
        fx[i] += gx, fy[i] += gy, fz[i] += gz;
        if constexpr (Rot) tx[i] += L.tx[l], ty[i] += L.ty[l], tz[i] += L.tz[l];
        wfx -= double(gx);
        wfy -= double(gy);
        wfz -= double(gz);
        return true;
      };
      const auto kinematics = [&](const int l) {
        WallKinematics<Real> kin{};
        kin.d = L.d[l], kin.r = L.r[l];
        return kin;
      };
      Pass::template run<Energy, Advance>(c, L, histories(k, nc), 0, static_cast<std::uint32_t>(nc), t, find,
                                          load, add, kinematics);
      walls.force(w) = {wfx, wfy, wfz};
    }
    dissipated_ += t.dissipated + t.parted;
    if (Advance) sliding_ += t.sliding;
    return t.energy;
  }

  /// Candidates ahead whose particle data the finding loop asks for (lanes(): the candidates are spread
  /// over the particles, and their data no longer in cache since the pairs' pass).
  static constexpr std::size_t kAhead = 24;
  /// What the lanes read and write of a particle.
  template <bool Rot>
  static auto lane_arrays(const Particles<Real>& p) {
    std::array<const Real*, Rot ? 17 : 11> a{p.x.data(),        p.y.data(),  p.z.data(),  p.radius.data(),
                                             p.inv_mass.data(), p.vx.data(), p.vy.data(), p.vz.data(),
                                             p.fx.data(),       p.fy.data(), p.fz.data()};
    if constexpr (Rot) {
      a[11] = p.wx.data(), a[12] = p.wy.data(), a[13] = p.wz.data();
      a[14] = p.tx.data(), a[15] = p.ty.data(), a[16] = p.tz.data();
    }
    return a;
  }

  /// The lanes' inputs of particles i[l] against a wall moving at (vwx, vwy, vwz), but for the distances
  /// (L.d, from the finding loop: the lanes see the distance that found the contact).
  template <bool Rot>
  BASALT_WIDE_LANES static void gather(const Particles<Real>& p, const std::uint32_t* __restrict ii, Real vwx,
                                       Real vwy, Real vwz, Lanes& L) {
    const Real* __restrict rad = p.radius.data();
    const Real* __restrict im = p.inv_mass.data();
    const Real* __restrict vx = p.vx.data();
    const Real* __restrict vy = p.vy.data();
    const Real* __restrict vz = p.vz.data();
#pragma GCC ivdep
    for (int l = 0; l < kLaneWidth; ++l) {
      const std::uint32_t i = ii[l];
      L.r[l] = rad[i];
      L.im[l] = im[i];
      L.vx[l] = vx[i] - vwx, L.vy[l] = vy[i] - vwy, L.vz[l] = vz[i] - vwz;
    }
    if constexpr (Rot) {
      const Real* __restrict wx = p.wx.data();
      const Real* __restrict wy = p.wy.data();
      const Real* __restrict wz = p.wz.data();
#pragma GCC ivdep
      for (int l = 0; l < kLaneWidth; ++l) {
        const std::uint32_t i = ii[l];
        L.wx[l] = wx[i], L.wy[l] = wy[i], L.wz[l] = wz[i];
      }
    }
  }

  template <bool Energy, bool Advance, bool Rot>
  double loop_kinematic(Particles<Real>& p, Walls& walls) {
    walls_ = &walls;
    double energy = 0, dissipated = 0;
    std::size_t sliding = 0;
    const Real* __restrict x = p.x.data();
    const Real* __restrict y = p.y.data();
    const Real* __restrict z = p.z.data();
    const Real* __restrict rad = p.radius.data();
    const Real* __restrict im = p.inv_mass.data();
    const Real* __restrict vx = p.vx.data();
    const Real* __restrict vy = p.vy.data();
    const Real* __restrict vz = p.vz.data();
    Real* __restrict fx = p.fx.data();
    Real* __restrict fy = p.fy.data();
    Real* __restrict fz = p.fz.data();
    [[maybe_unused]] const Real* __restrict wx = Rot ? p.wx.data() : nullptr;
    [[maybe_unused]] const Real* __restrict wy = Rot ? p.wy.data() : nullptr;
    [[maybe_unused]] const Real* __restrict wz = Rot ? p.wz.data() : nullptr;
    [[maybe_unused]] Real* __restrict tx = Rot ? p.tx.data() : nullptr;
    [[maybe_unused]] Real* __restrict ty = Rot ? p.ty.data() : nullptr;
    [[maybe_unused]] Real* __restrict tz = Rot ? p.tz.data() : nullptr;
    WallKinematics<Real> kin{};
    kin.dt = dt_;
    for (std::size_t k = 0; k < index_.size(); ++k) {
      const std::size_t w = index_[k];
      const auto c = coeffs_[k];
      const auto [nx, ny, nz, px, py, pz, vwx, vwy, vwz] = plane(walls, w);
      kin.nx = nx, kin.ny = ny, kin.nz = nz;
      double wfx = 0, wfy = 0, wfz = 0;
      const auto& cand = walls.candidates(w);
      History* __restrict hs = histories(k, cand.size());
      const auto* __restrict ci_of = cand.data();
      const std::size_t nc = cand.size();
      for (std::size_t ci = 0; ci < nc; ++ci) {
        const auto i = static_cast<std::size_t>(ci_of[ci]);
        History& h = hs[ci];
        kin.d = (x[i] - px) * kin.nx + (y[i] - py) * kin.ny + (z[i] - pz) * kin.nz;
        kin.r = rad[i];
        if (!(kin.d < kin.r)) {
          if constexpr (Advance) {
            dissipated += Model::parting_energy(c, h);
            h = History{};
          }
          continue;
        }
        kin.im = im[i];
        kin.vx = vx[i] - vwx, kin.vy = vy[i] - vwy, kin.vz = vz[i] - vwz;
        if constexpr (Rot) kin.wx = wx[i], kin.wy = wy[i], kin.wz = wz[i];
        ContactForce<Real> f;
        Model::template contact<Advance>(c, h, kin, f);
        fx[i] += f.fx;
        fy[i] += f.fy;
        fz[i] += f.fz;
        if constexpr (Rot) {  // (c - x) x F with c - x = -arm n
          const auto t = arm_torque(-f.arm_i, kin.nx, kin.ny, kin.nz, f);
          tx[i] += t.x, ty[i] += t.y, tz[i] += t.z;
        }
        wfx -= double(f.fx);
        wfy -= double(f.fy);
        wfz -= double(f.fz);
        if constexpr (Advance) {
          dissipated += f.dissipated;
          sliding += f.sliding;
        }
        if constexpr (Energy) energy += double(Model::energy(c, h, kin));
      }
      walls.force(w) = {wfx, wfy, wfz};
    }
    dissipated_ += dissipated;
    if (Advance) sliding_ += sliding;
    return energy;
  }

  using Pass = LanePass<Real, Model, Lanes>;
  struct NoLanes {};
  [[no_unique_address]] std::conditional_t<kLanes, Lanes, NoLanes> lanes_{};  ///< (with contact_lanes)
  using Base::coeffs_, Base::pending_, Base::dissipated_, Base::sliding_, Base::dt_;
  std::vector<std::size_t> index_;          ///< the walls this model acts through
  std::vector<std::vector<History>> hist_;  ///< per wall of this model, per candidate
  const Walls* walls_ = nullptr;
};

}  // namespace basalt::solver
