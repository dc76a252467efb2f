#pragma once
// Loops a wall model over the scene's mesh walls that use it ([[mesh_walls]], docs/mesh-walls.md) and
// the owned particles within reach of each (Walls::mesh_candidates). Each contact the mesh gives
// (ContactMesh::contacts: a point, a normal, an overlap; each touching point once) is what a planar
// wall contact is, with the plane through the contact point along the contact normal: the model's
// force law is applied to it unchanged (d = the centre's distance from the point), the torque acts at
// the contact point, the wall's velocity there (translation + omega x (q - axis point)) enters the
// friction. The force on each mesh and the power it puts in are tallied; owned particles only.
//
// History (friction): per (particle, mesh) pair, a short list of slots, one per contact the pair had
// at the last step, saved and restored like a planar wall's as records (particle id, -1 - (number of
// planar walls + mesh index)), one record per slot in slot order, so checkpoints and migration carry
// them unchanged. Contacts are matched to the slots each step by the slot's shear force being closest
// to tangent to the contact (smallest |s.n| / |s|), greedily over all pairs, ties by slot then contact
// order; unmatched slots part (their spring energy is dissipated), unmatched contacts start fresh. A
// particle with one contact (the usual case, and every contact on a flat mesh however it rolls over
// edges and vertices) keeps its history as on a planar wall. The slots are stored in contact order, so
// the state depends on nothing but the contacts and the saved histories (the same on any number of
// ranks and after a restart).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string_view>
#include <vector>

#include "basalt/solver/interactions/driver_base.hpp"
#include "basalt/solver/interactions/history_records.hpp"

namespace basalt::solver {

template <class Real, class Model>
class MeshWallDriver final : public ContactDriver<Real, Model, MeshWallDriver<Real, Model>> {
  using Base = ContactDriver<Real, Model, MeshWallDriver<Real, Model>>;

 public:
  using Coeffs = typename Base::Coeffs;
  using History = typename Base::History;
  static constexpr bool kKinematic = (Model::reads & kVelocity) != 0;
  using Base::kHistory;
  /// Contacts per (particle, mesh) pair whose history is kept (a sphere in a box's corner has three;
  /// in the silo's floor-wall corner up to four, two wall facets and the floor); more start fresh.
  static constexpr std::size_t kSlots = 4;

  /// Takes the scene's mesh walls whose model is Model; their history ids follow the planar walls'.
  MeshWallDriver(const std::vector<MeshWallSpec>& meshes, std::size_t planar_walls) : planar_(planar_walls) {
    for (std::size_t w = 0; w < meshes.size(); ++w) {
      if (meshes[w].model != Model::name) continue;
      index_.push_back(w);
      this->add_group(meshes[w].template params_of<Model>());
    }
    hist_.resize(index_.size());
  }

  double compute(ForceState<Real>& s, Part part, bool energy, bool advance) override {
    if (part != Part::owned) return 0;
    this->start_step(part, advance);
    walls_ = &s.walls;
    if constexpr (kKinematic) {
      if (advance) return energy ? loop<true, true>(s.p, s.walls) : loop<false, true>(s.p, s.walls);
      return energy ? loop<true, false>(s.p, s.walls) : loop<false, false>(s.p, s.walls);
    } else {
      return energy ? loop<true, false>(s.p, s.walls) : loop<false, false>(s.p, s.walls);
    }
  }

  void rebuild_walls(const Particles<Real>& p, const Walls& walls) override {
    walls_ = &walls;
    if constexpr (kHistory) {
      std::vector<std::uint32_t> order;
      pending_.index(order);
      for (std::size_t k = 0; k < index_.size(); ++k) {
        const auto& cand = walls.mesh_candidates(index_[k]);
        auto& h = hist_[k];
        h.assign(cand.size(), Slots{});
        if (pending_.empty()) continue;
        const std::int64_t wid = wall_id(k);
        for (std::size_t c = 0; c < cand.size(); ++c) {
          const std::int64_t pid = p.id[static_cast<std::size_t>(cand[c])];
          // The records of (wall id, particle id) in saved order (the index sorts by the unordered
          // pair, stably): wall ids are negative, so the pair reads (wall id, particle id).
          auto it =
              std::lower_bound(order.begin(), order.end(), pid, [&](std::uint32_t r, std::int64_t want) {
                const auto lo = std::min(pending_.a[r], pending_.b[r]),
                           hi = std::max(pending_.a[r], pending_.b[r]);
                return lo != wid ? lo < wid : hi < want;
              });
          for (; it != order.end() && h[c].n < kSlots; ++it) {
            const auto r = *it;
            if (std::min(pending_.a[r], pending_.b[r]) != wid ||
                std::max(pending_.a[r], pending_.b[r]) != pid)
              break;
            std::memcpy(static_cast<void*>(&h[c].h[h[c].n++]), pending_.at(r), sizeof(History));
          }
        }
      }
      pending_.clear();
    }
  }
  /// The records of the meshes' contacts, one per slot in slot order (ContactDriver: save_history,
  /// history_records).
  void collect(const Particles<Real>& p, ContactRecords& out) const {
    out.width = history_width<Model>();
    if (!walls_) return;
    for (std::size_t k = 0; k < index_.size(); ++k) {
      const auto& cand = walls_->mesh_candidates(index_[k]);
      for (std::size_t c = 0; c < cand.size() && c < hist_[k].size(); ++c)
        for (std::size_t s = 0; s < hist_[k][c].n; ++s)
          out.push(p.id[static_cast<std::size_t>(cand[c])], wall_id(k),
                   reinterpret_cast<const double*>(&hist_[k][c].h[s]));
    }
  }
  std::size_t memory_bytes() const override {
    std::size_t b = 0;
    for (const auto& h : hist_) b += h.capacity() * sizeof(Slots);
    return b;
  }

 private:
  struct Slots {
    std::array<History, kSlots> h{};
    std::size_t n = 0;  ///< slots in use, first n
  };

  /// The second id of a mesh contact's record: -1 - (planar walls + the mesh's index in the scene).
  std::int64_t wall_id(std::size_t k) const { return wall_record_id(planar_ + index_[k]); }

  /// slot_of[j]: the slot of `old` contact j takes, or -1 (fresh). Greedy over (slot, contact) pairs
  /// by |s.n| / |s| ascending.
  static void match(const Slots& old, const std::vector<MeshContact>& cs, std::array<int, 16>& slot_of) {
    const std::size_t nc = std::min<std::size_t>(cs.size(), slot_of.size());
    for (std::size_t j = 0; j < nc; ++j) slot_of[j] = -1;
    if (old.n == 0) return;
    if (old.n == 1 && nc == 1) {
      slot_of[0] = 0;
      return;
    }
    struct Cand {
      double score;
      std::uint32_t s, j;
    };
    std::array<Cand, kSlots * 16> all{};
    std::size_t na = 0;
    for (std::uint32_t s = 0; s < old.n; ++s) {
      // Every wall model's History starts with its tangential vector (shear force or displacement).
      const double* h = reinterpret_cast<const double*>(&old.h[s]);
      const double m = std::sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
      for (std::uint32_t j = 0; j < nc; ++j) {
        const auto& n = cs[j].normal;
        const double sc = m > 0 ? std::abs(h[0] * n[0] + h[1] * n[1] + h[2] * n[2]) / m : 0.0;
        all[na++] = {sc, s, j};
      }
    }
    std::stable_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(na),
                     [](const Cand& a, const Cand& b) { return a.score < b.score; });
    std::array<char, kSlots> used{};
    for (std::size_t q = 0; q < na; ++q) {
      const auto& c = all[q];
      if (used[c.s] || slot_of[c.j] >= 0) continue;
      used[c.s] = 1;
      slot_of[c.j] = static_cast<int>(c.s);
    }
  }

  template <bool Energy, bool Advance>
  double loop(Particles<Real>& p, Walls& walls) {
    double energy = 0, dissipated = 0;
    std::size_t sliding = 0;
    const bool rot = p.with_rotation;
    thread_local std::vector<MeshContact> cs;
    for (std::size_t k = 0; k < index_.size(); ++k) {
      const std::size_t w = index_[k];
      const auto& mesh = walls.mesh(w);
      const auto& c = coeffs_[k];
      const bool moves = walls.mesh_spec(w).moves();
      double wfx = 0, wfy = 0, wfz = 0, power = 0;
      const auto& cand = walls.mesh_candidates(w);
      auto& hist = hist_[k];
      if constexpr (kHistory)
        if (hist.size() != cand.size()) hist.assign(cand.size(), Slots{});
      for (std::size_t ci = 0; ci < cand.size(); ++ci) {
        const auto i = static_cast<std::size_t>(cand[ci]);
        cs.clear();
        mesh.contacts({double(p.x[i]), double(p.y[i]), double(p.z[i])}, double(p.radius[i]), cs);
        if constexpr (kHistory) {
          if (cs.empty() && hist[ci].n == 0) continue;
        } else {
          if (cs.empty()) continue;
        }
        [[maybe_unused]] std::array<int, 16> slot_of{};
        [[maybe_unused]] Slots next{};
        if constexpr (kHistory) match(hist[ci], cs, slot_of);
        for (std::size_t j = 0; j < cs.size(); ++j) {
          const MeshContact& mc = cs[j];
          const Real nx = Real(mc.normal[0]), ny = Real(mc.normal[1]), nz = Real(mc.normal[2]);
          ContactForce<Real> f;
          std::array<double, 3> vw{0, 0, 0};
          if (moves) vw = walls.mesh_velocity_at(w, mc.point);
          if constexpr (kKinematic) {
            WallKinematics<Real> kin{};
            kin.dt = dt_;
            kin.nx = nx, kin.ny = ny, kin.nz = nz;
            kin.d = Real(mc.distance);
            kin.r = p.radius[i];
            kin.im = p.inv_mass[i];
            kin.vx = p.vx[i] - Real(vw[0]), kin.vy = p.vy[i] - Real(vw[1]), kin.vz = p.vz[i] - Real(vw[2]);
            if (rot) kin.wx = p.wx[i], kin.wy = p.wy[i], kin.wz = p.wz[i];
            History h{};
            if constexpr (kHistory)
              if (j < slot_of.size() && slot_of[j] >= 0) h = hist[ci].h[static_cast<std::size_t>(slot_of[j])];
            Model::template contact<Advance>(c, h, kin, f);
            if constexpr (kHistory)
              if (holds(h) && next.n < kSlots) next.h[next.n++] = h;
            if constexpr (Advance) {
              dissipated += f.dissipated;
              sliding += f.sliding;
            }
            if constexpr (Energy) energy += double(Model::energy(c, h, kin));
          } else {
            const Real o = p.radius[i] - Real(mc.distance);
            if (!(o > 0)) continue;
            const Real fn = Model::force(c, p.radius[i], o);
            f.fx = fn * nx, f.fy = fn * ny, f.fz = fn * nz;
            f.arm_i = Real(mc.distance);
            if constexpr (Energy) energy += double(Model::energy(c, p.radius[i], o));
          }
          p.fx[i] += f.fx;
          p.fy[i] += f.fy;
          p.fz[i] += f.fz;
          if (rot) {  // (q - x) x F with q - x = -arm n
            const auto t = arm_torque(-f.arm_i, nx, ny, nz, f);
            p.tx[i] += t.x, p.ty[i] += t.y, p.tz[i] += t.z;
          }
          wfx -= double(f.fx);
          wfy -= double(f.fy);
          wfz -= double(f.fz);
          if (moves) power += double(f.fx) * vw[0] + double(f.fy) * vw[1] + double(f.fz) * vw[2];
        }
        if constexpr (kHistory) {
          if constexpr (Advance) {
            // Slots no contact took part: their stored spring energy is dissipated.
            std::array<char, kSlots> taken{};
            for (std::size_t j = 0; j < cs.size() && j < slot_of.size(); ++j)
              if (slot_of[j] >= 0) taken[static_cast<std::size_t>(slot_of[j])] = 1;
            for (std::size_t s = 0; s < hist[ci].n; ++s)
              if (!taken[s]) dissipated += Model::parting_energy(c, hist[ci].h[s]);
            hist[ci] = next;
          }
        }
      }
      walls.mesh_force(w) = {wfx, wfy, wfz};
      walls.mesh_power(w) = power;
    }
    dissipated_ += dissipated;
    if (Advance) sliding_ += sliding;
    return energy;
  }

  std::size_t planar_ = 0;  ///< planar walls in the scene (mesh history ids follow theirs)
  using Base::coeffs_, Base::pending_, Base::dissipated_, Base::sliding_, Base::dt_;
  std::vector<std::size_t> index_;        ///< the mesh walls this model acts through
  std::vector<std::vector<Slots>> hist_;  ///< per mesh of this model, per candidate
  const Walls* walls_ = nullptr;
};

}  // namespace basalt::solver
