#pragma once
// Loops a contact model over the Verlet pair lists. Owned-owned pairs apply Newton's third law once;
// owned-ghost pairs give force to the owned particle only (the ghost's owner computes the same pair).
// Energies are tallied by the rank owning the smaller global id. With one group that takes every tag
// the per-pair group lookup is skipped. A model with per-contact History gets it stored beside the
// list (one entry per listed pair), carried across rebuilds by the pair's ids (contact_history.hpp),
// and advanced only on real steps: Model::advance updates it for interacting pairs, Model::apart for
// listed pairs that do not interact, and Model::force reads it. A pair interacts when the model's
// touching() says so (default: the spheres overlap); the model contract is models/contract.hpp.
#include <cmath>
#include <concepts>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "basalt/solver/interactions/driver_base.hpp"
#include "basalt/solver/interactions/history_records.hpp"
#include "basalt/solver/interactions/lane_pass.hpp"
#include "basalt/solver/models/contract.hpp"
#include "basalt/solver/models/lanes.hpp"

namespace basalt::solver {

namespace detail {
/// Eight values of Real and eight indices of its width: the operands of a permutation
/// (PairDriver::first_ends).
template <class Real>
struct Eight;
template <>
struct Eight<double> {
  using Index = std::int64_t;
  typedef double V __attribute__((vector_size(64)));
  typedef std::int64_t M __attribute__((vector_size(64)));
};
template <>
struct Eight<float> {
  using Index = std::int32_t;
  typedef float V __attribute__((vector_size(32)));
  typedef std::int32_t M __attribute__((vector_size(32)));
};
}  // namespace detail

template <class Real, class Model>
class PairDriver final : public ContactDriver<Real, Model, PairDriver<Real, Model>> {
  using Base = ContactDriver<Real, Model, PairDriver<Real, Model>>;

 public:
  using Coeffs = typename Base::Coeffs;
  using History = typename Base::History;
  using Base::kHistory;
  /// A model reading velocities gets the pair's kinematics and returns a force vector and torques
  /// (loop_kinematic); the others a scalar force along the line of centres (loop).
  static constexpr bool kKinematic = (Model::reads & kVelocity) != 0;

  /// Takes the scene's pair groups of model Model.
  explicit PairDriver(const std::vector<InteractionSpec>& groups) {
    for (const auto& g : groups) {
      if (g.model != Model::name) continue;
      this->add_group(g.template params_of<Model>());
      tags_.push_back(g.tags);
      names_.push_back(g.name);
    }
    uniform_ = tags_.size() == 1 && tags_[0].empty();
  }

  /// New parameters for the group g.name (its tags stay: the lists' split among models is the rebuild's).
  /// Contact histories stay as they are: the model reads them with the new parameters from the next step.
  bool reconfigure(const InteractionSpec& g) override {
    for (std::size_t k = 0; k < names_.size(); ++k)
      if (names_[k] == g.name && g.model == Model::name) {
        this->set_group(k, g.template params_of<Model>());
        return true;
      }
    return false;
  }

  /// Group taking a pair of particles with these tags, or -1.
  int group_of(std::int64_t ti, std::int64_t tj) const {
    for (std::size_t g = 0; g < tags_.size(); ++g) {
      const auto& t = tags_[g];
      if (t.empty() || (t[0] == ti && t[1] == tj) || (t[0] == tj && t[1] == ti)) return static_cast<int>(g);
    }
    return -1;
  }
  /// One group for every pair of tags.
  bool takes_all() const { return uniform_; }

  double reach(double rmax) const override {
    return this->largest([rmax](const typename Model::Params& p) { return pair_reach<Model>(p, rmax); });
  }
  double compute(ForceState<Real>& s, Part part, bool energy, bool advance) override {
    const bool own = part == Part::owned;
    this->start_step(part, advance);
    const PairList& list = own ? *own_ : *ghost_;
    History* h = own ? hist_own_.data() : hist_ghost_.data();
    if constexpr (kLanes) rows_ = own ? row_own_.data() : row_ghost_.data();
    if (own) return dispatch<true>(s.p, list, h, energy, advance);
    return dispatch<false>(s.p, list, h, energy, advance);
  }

  void rebuild(const PairLists<Real>& l, std::size_t index) override {
    if (l.computes == 1) {
      own_ = &l.own;
      ghost_ = &l.ghost;
    } else {
      filter(l, l.own, index, own_sub_);
      filter(l, l.ghost, index, ghost_sub_);
      own_ = &own_sub_;
      ghost_ = &ghost_sub_;
    }
    if constexpr (kLanes) {
      row_of(*own_, row_own_);
      row_of(*ghost_, row_ghost_);
    }
    if constexpr (kHistory) {
      const ContactLookup records(pending_);
      restore_pairs<Model>(l.p, *own_, pending_, records, hist_own_);
      restore_pairs<Model>(l.p, *ghost_, pending_, records, hist_ghost_);
      pending_.clear();
      drop_bonded(l.p, *own_, hist_own_, true);
      drop_bonded(l.p, *ghost_, hist_ghost_, false);
    }
  }

  /// The records of the listed contacts (ContactDriver: save_history, history_records): the pairs to a
  /// ghost too, as the other rank saves its own history of each (contact_history.hpp).
  void collect(const Particles<Real>& p, ContactRecords& out) const {
    if (own_ == nullptr) return;
    collect_pairs<Model>(p, *own_, hist_own_, out);
    collect_pairs<Model>(p, *ghost_, hist_ghost_, out);
  }
  /// The model has a closed-form collision (Model::collision, stability/impact.hpp).
  static constexpr bool kCollides = requires(const typename Base::Params& q) {
    { Model::collision(q, 1.0, 1.0, 1.0, 0.0) } -> std::same_as<Collision>;
  };
  bool sees_impacts() const override { return kCollides; }
  /// Every listed unbonded pair of an owned particle, touching or meeting along straight paths: the
  /// collision of fewest steps, and the counts of collisions whose overlap passes 5 % and 20 % of the
  /// smaller radius (a pair across ranks counted by the rank owning the lower id).
  CollisionSeen shortest_collision(const Particles<Real>& p, const Walls&, double dt,
                                   const std::vector<std::int64_t>& fixed) const override {
    CollisionSeen worst;
    if constexpr (kCollides) {
      if (own_ == nullptr) return worst;
      for (const PairList* list : {own_, ghost_})
        for (std::size_t i = 0; i + 1 < list->offset.size() && i < p.n_owned; ++i)
          for (auto e = list->offset[i]; e < list->offset[i + 1]; ++e) {
            if (list->is_bonded(e)) continue;
            const auto j = static_cast<std::size_t>(list->neigh[e]);
            const double d[3] = {double(p.x[i]) - double(p.x[j]), double(p.y[i]) - double(p.y[j]),
                                 double(p.z[i]) - double(p.z[j])};
            const double u[3] = {double(p.vx[i]) - double(p.vx[j]), double(p.vy[i]) - double(p.vy[j]),
                                 double(p.vz[i]) - double(p.vz[j])};
            const double ri = double(p.radius[i]), rj = double(p.radius[j]);
            double vn = 0, overlap = 0;
            if (!approach(d, u, ri + rj, vn, overlap)) continue;
            const auto g = uniform_ ? 0 : group_of(p.tag[i], p.tag[j]);
            if (g < 0) continue;
            const double m = 1 / ((fixed_tag(fixed, p.tag[i]) ? 0.0 : double(p.inv_mass[i])) +
                                  (fixed_tag(fixed, p.tag[j]) ? 0.0 : double(p.inv_mass[j])));
            const Collision c = Model::collision(this->params_[static_cast<std::size_t>(g)],
                                                 ri * rj / (ri + rj), m, vn, overlap);
            if (!(c.duration > 0)) continue;
            if (list == own_ || p.id[i] < p.id[j]) worst.count(c.overlap, std::min(ri, rj));  // once per pair
            if (!(c.duration / dt < worst.steps)) continue;
            worst.set(c, dt, ri, rj, p.id[i], p.id[j], -1);
          }
    }
    return worst;
  }
  std::size_t contacts() const override { return own_ ? own_->pairs() + ghost_->pairs() : 0; }
  std::size_t memory_bytes() const override {
    std::size_t b = (hist_own_.capacity() + hist_ghost_.capacity()) * basalt::solver::history_bytes<Model>();
    if (own_ == &own_sub_) b += own_sub_.memory_bytes() + ghost_sub_.memory_bytes();
    b += (row_own_.capacity() + row_ghost_.capacity()) * sizeof(std::uint32_t);
    return b;
  }

 private:
  template <bool Newton>
  double dispatch(Particles<Real>& p, const PairList& list, History* h, bool energy, bool advance) {
    if constexpr (kKinematic) {
      if (advance)
        return energy ? loop_kinematic<true, Newton, true>(p, list, h)
                      : loop_kinematic<false, Newton, true>(p, list, h);
      return energy ? loop_kinematic<true, Newton, false>(p, list, h)
                    : loop_kinematic<false, Newton, false>(p, list, h);
    } else {
      if constexpr (kHistory) {
        if (advance) {
          if (uniform_)
            return energy ? loop<true, true, Newton, true>(p, list, h, dissipated_)
                          : loop<false, true, Newton, true>(p, list, h, dissipated_);
          return energy ? loop<true, false, Newton, true>(p, list, h, dissipated_)
                        : loop<false, false, Newton, true>(p, list, h, dissipated_);
        }
      }
      if (uniform_)
        return energy ? loop<true, true, Newton, false>(p, list, h, dissipated_)
                      : loop<false, true, Newton, false>(p, list, h, dissipated_);
      return energy ? loop<true, false, Newton, false>(p, list, h, dissipated_)
                    : loop<false, false, Newton, false>(p, list, h, dissipated_);
    }
  }

  template <bool Energy, bool Uniform, bool Newton, bool Advance>
  double loop(Particles<Real>& p, const PairList& list, History* hist, double& dissipated) const {
    // (lists with bonded pairs marked get a loop of their own over the pairs not bonded: the wave
    // benchmark's has no indirection)
    return list.bonded.empty() ? loop_over<Energy, Uniform, Newton, Advance, false>(p, list, hist, dissipated)
                               : loop_over<Energy, Uniform, Newton, Advance, true>(p, list, hist, dissipated);
  }

  /// A scalar law's force and energy, of the sum of radii or of both radii (models/contract.hpp).
  static Real law_force(const Coeffs& c, const History& h, Real ri, Real rj, Real rsum, Real r) {
    if constexpr (contract::ScalarPairLawOfRadii<Model, Real>) {
      (void)rsum;
      return Model::force(c, h, ri, rj, r);
    } else {
      (void)ri, (void)rj;
      return Model::force(c, h, rsum, r);
    }
  }
  static Real law_energy(const Coeffs& c, const History& h, Real ri, Real rj, Real rsum, Real r) {
    if constexpr (contract::ScalarPairLawOfRadii<Model, Real>) {
      (void)rsum;
      return Model::energy(c, h, ri, rj, r);
    } else {
      (void)ri, (void)rj;
      return Model::energy(c, h, rsum, r);
    }
  }
  static void law_advance(const Coeffs& c, History& h, Real ri, Real rj, Real rsum, Real r) {
    if constexpr (contract::ScalarPairLawOfRadii<Model, Real>) {
      (void)rsum;
      Model::advance(c, h, ri, rj, r);
    } else {
      (void)ri, (void)rj;
      Model::advance(c, h, rsum, r);
    }
  }

  template <bool Energy, bool Uniform, bool Newton, bool Advance, bool Marked>
  /// Parting energies (models with a dissipation term) are added to `dissipated`.
  double loop_over(Particles<Real>& p, const PairList& list, [[maybe_unused]] History* hist,
                   [[maybe_unused]] double& dissipated) const {
    double energy = 0;
    [[maybe_unused]] double parted = 0;
    const std::size_t n = p.n_owned;
    const Real* __restrict x = p.x.data();
    const Real* __restrict y = p.y.data();
    const Real* __restrict z = p.z.data();
    const Real* __restrict rad = p.radius.data();
    Real* __restrict fx = p.fx.data();
    Real* __restrict fy = p.fy.data();
    Real* __restrict fz = p.fz.data();
    const std::uint32_t* __restrict off = list.offset.data();
    const std::int32_t* __restrict nb = list.neigh.data();
    // With bonded pairs listed, a row's entries not bonded (the bonded ones act by their bond).
    const std::uint32_t* __restrict from = Marked ? list.loose_offset.data() : off;
    [[maybe_unused]] const std::uint32_t* __restrict loose = list.loose.data();
    const Coeffs c0 = coeffs_.empty() ? Coeffs{} : coeffs_[0];
    for (std::size_t i = 0; i < n; ++i) {
      const Real xi = x[i], yi = y[i], zi = z[i], ri = rad[i];
      Real fxi = 0, fyi = 0, fzi = 0;
      for (auto q = from[i]; q < from[i + 1]; ++q) {
        const auto k = Marked ? loose[q] : q;
        const auto j = static_cast<std::size_t>(nb[k]);
        const Real dx = xi - x[j], dy = yi - y[j], dz = zi - z[j];
        const Real r2 = dx * dx + dy * dy + dz * dz;
        const Real rsum = ri + rad[j];
        // (the pair's coefficients are looked up only for pairs that interact, unless the model's own
        // touching() needs them)
        bool touch;
        if constexpr (kTouching) {
          History none{};
          touch = pair_touching<Model, Real>(
              Uniform ? c0 : coeffs_[static_cast<std::size_t>(group_of(p.tag[i], p.tag[j]))],
              kHistory ? hist[k] : none, ri, rad[j], r2);
        } else {
          touch = r2 < rsum * rsum;
        }
        if (!touch) {
          if constexpr (kHistory && Advance) {
            // What the history still held is lost with it: dissipated (models with a dissipation term).
            if constexpr (kDissipates)
              if (holds(hist[k]) && (Newton || p.id[i] < p.id[j]))
                parted += Model::parting_energy(
                    Uniform ? c0 : coeffs_[static_cast<std::size_t>(group_of(p.tag[i], p.tag[j]))], hist[k]);
            Model::apart(hist[k]);
          }
          continue;
        }
        const Coeffs& c = Uniform ? c0 : coeffs_[static_cast<std::size_t>(group_of(p.tag[i], p.tag[j]))];
        const Real r = std::sqrt(r2);
        History none{};
        History* hp = &none;
        if constexpr (kHistory) hp = &hist[k];
        History& h = *hp;
        const Real rj = rad[j];
        if constexpr (kHistory && Advance) law_advance(c, h, ri, rj, rsum, r);
        const Real s = law_force(c, h, ri, rj, rsum, r) / r;
        fxi += s * dx;
        fyi += s * dy;
        fzi += s * dz;
        if constexpr (Newton) {
          fx[j] -= s * dx;
          fy[j] -= s * dy;
          fz[j] -= s * dz;
        }
        if constexpr (Energy)
          if (Newton || p.id[i] < p.id[j]) energy += double(law_energy(c, h, ri, rj, rsum, r));
      }
      fx[i] += fxi;
      fy[i] += fyi;
      fz[i] += fzi;
    }
    if constexpr (kDissipates) dissipated += parted;
    return energy;
  }

  /// Velocity-dependent models: the pair's kinematics in, a force vector, its point of action and a
  /// couple out; torques only when the particles rotate. Dissipated energy accumulates on real steps
  /// (once per pair across ranks, as the energies). Rotation and one group for all pairs are
  /// template arguments (no per-pair test of either); particle i's force and torque add up in
  /// registers and reach memory once per row.
  template <bool Energy, bool Newton, bool Advance>
  double loop_kinematic(Particles<Real>& p, const PairList& list, History* hist) {
    const bool one = coeffs_.size() == 1;
    // The lanes take one group's coefficients for every pair: several groups (tags) go pair by pair.
    if constexpr (kLanes) {
      if (one) {
        // (with bonded pairs listed, the contact test reads their marks: a loop of its own, so that the
        // granular scenes' loop has not even the test of the marks' pointer)
        if (!list.bonded.empty())
          return p.with_rotation ? batches<Energy, Newton, Advance, true, true>(p, list, hist)
                                 : batches<Energy, Newton, Advance, false, true>(p, list, hist);
        return p.with_rotation ? batches<Energy, Newton, Advance, true, false>(p, list, hist)
                               : batches<Energy, Newton, Advance, false, false>(p, list, hist);
      }
    }
    if (p.with_rotation)
      return one ? rows<Energy, Newton, Advance, true, true>(p, list, hist)
                 : rows<Energy, Newton, Advance, true, false>(p, list, hist);
    return one ? rows<Energy, Newton, Advance, false, true>(p, list, hist)
               : rows<Energy, Newton, Advance, false, false>(p, list, hist);
  }

  template <bool Energy, bool Newton, bool Advance, bool Rot, bool One>
  double rows(Particles<Real>& p, const PairList& list, History* hist) {
    // (as loop(): a frictional scene without breakable bonds has no indirection per pair)
    return list.bonded.empty() ? rows_over<Energy, Newton, Advance, Rot, One, false>(p, list, hist)
                               : rows_over<Energy, Newton, Advance, Rot, One, true>(p, list, hist);
  }

  template <bool Energy, bool Newton, bool Advance, bool Rot, bool One, bool Marked>
  double rows_over(Particles<Real>& p, const PairList& list, [[maybe_unused]] History* hist) {
    double energy = 0, dissipated = 0;
    std::size_t sliding = 0;
    const std::size_t n = p.n_owned;
    const std::uint32_t* __restrict off = list.offset.data();
    const std::int32_t* __restrict nb = list.neigh.data();
    // With bonded pairs listed, a row's entries not bonded (the bonded ones act by their bond; in an
    // intact rock they are most of the list).
    const std::uint32_t* __restrict from = Marked ? list.loose_offset.data() : off;
    [[maybe_unused]] const std::uint32_t* __restrict loose = list.loose.data();
    const Real* __restrict x = p.x.data();
    const Real* __restrict y = p.y.data();
    const Real* __restrict z = p.z.data();
    const Real* __restrict rad = p.radius.data();
    const Real* __restrict im = p.inv_mass.data();
    const Real* __restrict vx = p.vx.data();
    const Real* __restrict vy = p.vy.data();
    const Real* __restrict vz = p.vz.data();
    const std::int64_t* __restrict id = p.id.data();
    Real* __restrict fx = p.fx.data();
    Real* __restrict fy = p.fy.data();
    Real* __restrict fz = p.fz.data();
    [[maybe_unused]] const Real* __restrict wx = Rot ? p.wx.data() : nullptr;
    [[maybe_unused]] const Real* __restrict wy = Rot ? p.wy.data() : nullptr;
    [[maybe_unused]] const Real* __restrict wz = Rot ? p.wz.data() : nullptr;
    [[maybe_unused]] Real* __restrict tx = Rot ? p.tx.data() : nullptr;
    [[maybe_unused]] Real* __restrict ty = Rot ? p.ty.data() : nullptr;
    [[maybe_unused]] Real* __restrict tz = Rot ? p.tz.data() : nullptr;
    const Coeffs c0 = coeffs_.empty() ? Coeffs{} : coeffs_[0];
    const auto coeffs_of = [&](std::size_t i, std::size_t j) -> const Coeffs& {
      if constexpr (One) return c0;
      return coeffs_[static_cast<std::size_t>(group_of(p.tag[i], p.tag[j]))];
    };
    ContactKinematics<Real> k{};
    k.dt = dt_;
    for (std::size_t i = 0; i < n; ++i) {
      // Most rows of the ghost list, and in an intact rock most rows of the loose pairs: nothing to add (the
      // sums start at +0 and no addition turns them to -0, so adding a zero row's +0 changes no bit).
      if (from[i] == from[i + 1]) continue;
      const Real xi = x[i], yi = y[i], zi = z[i], ri = rad[i], imi = im[i];
      const Real vxi = vx[i], vyi = vy[i], vzi = vz[i];
      Real fxi = 0, fyi = 0, fzi = 0, txi = 0, tyi = 0, tzi = 0;
      if constexpr (Rot) k.wix = wx[i], k.wiy = wy[i], k.wiz = wz[i];
      for (auto q = from[i]; q < from[i + 1]; ++q) {
        const auto e = Marked ? loose[q] : q;
        const auto j = static_cast<std::size_t>(nb[e]);
        const Real dx = xi - x[j], dy = yi - y[j], dz = zi - z[j];
        const Real r2 = dx * dx + dy * dy + dz * dz;
        const Real rj = rad[j], rsum = ri + rj;
        History none{};
        History& h = kHistory ? hist[e] : none;
        if (!(kTouching ? pair_touching<Model, Real>(coeffs_of(i, j), h, ri, rj, r2) : r2 < rsum * rsum)) {
          if constexpr (kHistory && Advance) {
            // What the history still held is lost with it (a shear spring's energy): dissipated. Most
            // pairs here were apart or bonded the step before too: their history is clear already.
            if (holds(h)) [[unlikely]] {
              if (Newton || id[i] < id[j]) dissipated += Model::parting_energy(coeffs_of(i, j), h);
              Model::apart(h);
            }
          }
          continue;
        }
        const Coeffs& c = coeffs_of(i, j);
        k.dx = dx, k.dy = dy, k.dz = dz;
        k.r = std::sqrt(r2);
        k.ri = ri, k.rj = rj;
        k.imi = imi, k.imj = im[j];
        k.vx = vxi - vx[j], k.vy = vyi - vy[j], k.vz = vzi - vz[j];
        if constexpr (Rot) k.wjx = wx[j], k.wjy = wy[j], k.wjz = wz[j];
        ContactForce<Real> f;
        Model::template contact<Advance>(c, h, k, f);
        fxi += f.fx;
        fyi += f.fy;
        fzi += f.fz;
        if constexpr (Newton) {
          fx[j] -= f.fx;
          fy[j] -= f.fy;
          fz[j] -= f.fz;
        }
        if constexpr (Rot) {
          // Arms: c - x_i = -arm_i n, c - x_j = (r - arm_i) n, n = d / r (j's torque is minus its arm's).
          const Real inv_r = Real(1) / k.r;  // the model's own 1 / r, computed once
          const auto ti = arm_torque(-f.arm_i * inv_r, dx, dy, dz, f);
          txi += ti.x;
          tyi += ti.y;
          tzi += ti.z;
          if constexpr (Newton) {
            const auto tj = arm_torque((k.r - f.arm_i) * inv_r, dx, dy, dz, f);
            tx[j] -= tj.x;
            ty[j] -= tj.y;
            tz[j] -= tj.z;
          }
        }
        if (Newton || id[i] < id[j]) {
          if constexpr (Advance) {
            dissipated += f.dissipated;
            sliding += f.sliding;
          }
          if constexpr (Energy) energy += double(Model::energy(c, h, k));
        }
      }
      fx[i] += fxi;
      fy[i] += fyi;
      fz[i] += fzi;
      if constexpr (Rot) {
        tx[i] += txi;
        ty[i] += tyi;
        tz[i] += tzi;
      }
    }
    dissipated_ += dissipated;
    sliding_ += sliding;
    return energy;
  }

  /// rows() for a model with contact_lanes and one group: the listed pairs in list order through the lane
  /// pass (lane_pass.hpp), their forces and torques added in list order to both particles in memory (summing
  /// particle i's row in registers, as rows() does, cost a mispredicted branch at every row's end: 0.92x the
  /// time without it).
  template <bool Energy, bool Newton, bool Advance, bool Rot, bool Marked>
  double batches(Particles<Real>& p, const PairList& list, [[maybe_unused]] History* hist) {
    const std::size_t n = p.n_owned;
    if (n == 0) return 0;  // (a rank without particles may have no list offsets at all)
    const std::uint32_t* __restrict off = list.offset.data();
    const std::int32_t* __restrict nb = list.neigh.data();
    [[maybe_unused]] const std::uint8_t* __restrict bonded = list.bonded.data();
    const std::int64_t* __restrict id = p.id.data();
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
    const Coeffs c = coeffs_[0];
    auto& L = lanes_;
    L.dt = dt_;
    // A batch's pairs: row and neighbour. The finding loop writes nothing else (a store per value costs more
    // than loading it again): gather() loads the lanes' inputs from these, kLaneWidth at a time in vector
    // registers.
    alignas(64) std::uint32_t lane_i[kLaneWidth], lane_j[kLaneWidth];
    // The pairs in contact are found with positions and radii alone, written to the next lane whether they
    // touch or not: no branch to mispredict, and little work for a listed pair apart (a third of them in a
    // settled pile). One loop over the listed pairs, each pair's row read from rows_ (a loop per row
    // mispredicted its end at nearly every row: a settled pile's rows have 3 or 4 pairs).
    const std::uint32_t* __restrict row = rows_;
    const auto find = [&](const std::uint32_t e, const int l) {
      const std::uint32_t i = row[e];
      const auto j = static_cast<std::uint32_t>(nb[e]);
      const Real dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
      const Real r2 = dx * dx + dy * dy + dz * dz;
      const Real rsum = rad[i] + rad[j];
      bool touch = r2 < rsum * rsum;
      if constexpr (Marked) touch = touch && bonded[e] == 0;  // (a bonded pair acts by its bond)
      lane_i[l] = i, lane_j[l] = j;
      return LaneFound{touch, Newton || id[i] < id[j]};
    };
    const auto load = [&](const int filled) {
      Pass::pad(lane_i, filled), Pass::pad(lane_j, filled);
      gather<Rot>(p, lane_i, lane_j, L);
    };
    const auto add = [&](const int l) {
      const std::size_t i = lane_i[l], j = lane_j[l];
      const Real gx = L.fx[l], gy = L.fy[l], gz = L.fz[l];
      fx[i] += gx, fy[i] += gy, fz[i] += gz;
      if constexpr (Newton) fx[j] -= gx, fy[j] -= gy, fz[j] -= gz;
      if constexpr (Rot) {
        tx[i] += L.tix[l], ty[i] += L.tiy[l], tz[i] += L.tiz[l];
        if constexpr (Newton) tx[j] += L.tjx[l], ty[j] += L.tjy[l], tz[j] += L.tjz[l];
      }
      return Newton || id[i] < id[j];
    };
    const auto kinematics = [&](const int l) {
      ContactKinematics<Real> k{};
      k.dx = L.dx[l], k.dy = L.dy[l], k.dz = L.dz[l], k.r = L.r[l], k.ri = L.ri[l], k.rj = L.rj[l];
      return k;
    };
    LaneTally t;
    Pass::template run<Energy, Advance>(c, L, hist, off[0], off[n], t, find, load, add, kinematics);
    dissipated_ += t.dissipated + t.parted;
    sliding_ += t.sliding;
    return t.energy;
  }

  /// The lanes' particle inputs of pairs (i[l], j[l]), loaded in vector registers. The lanes take
  /// dx = x_i - x_j and r2 from here, not from the finding loop (whose r2 only decides whether the pair
  /// touches). The first particles come in row order, so eight lanes' usually lie within eight consecutive
  /// particles: their values are one vector load of each array and a permutation (first_ends), not a
  /// gather of eight loads; the second particles are gathered.
  template <bool Rot, class Lanes>
  BASALT_WIDE_LANES static void gather(const Particles<Real>& p, const std::uint32_t* __restrict ii,
                                       const std::uint32_t* __restrict jj, Lanes& L) {
    alignas(64) Real xi[kLaneWidth], yi[kLaneWidth], zi[kLaneWidth], vxi[kLaneWidth], vyi[kLaneWidth],
        vzi[kLaneWidth];
    first_ends<Rot>(p, ii, L, xi, yi, zi, vxi, vyi, vzi);
    const Real* __restrict x = p.x.data();
    const Real* __restrict y = p.y.data();
    const Real* __restrict z = p.z.data();
    const Real* __restrict rad = p.radius.data();
    const Real* __restrict im = p.inv_mass.data();
    const Real* __restrict vx = p.vx.data();
    const Real* __restrict vy = p.vy.data();
    const Real* __restrict vz = p.vz.data();
#pragma GCC ivdep
    for (int l = 0; l < kLaneWidth; ++l) {
      const std::uint32_t j = jj[l];
      const Real dx = xi[l] - x[j], dy = yi[l] - y[j], dz = zi[l] - z[j];
      L.dx[l] = dx, L.dy[l] = dy, L.dz[l] = dz;
      L.r2[l] = dx * dx + dy * dy + dz * dz;
      L.rj[l] = rad[j];
      L.imj[l] = im[j];
      L.vx[l] = vxi[l] - vx[j], L.vy[l] = vyi[l] - vy[j], L.vz[l] = vzi[l] - vz[j];
    }
    if constexpr (Rot) {
      const Real* __restrict wx = p.wx.data();
      const Real* __restrict wy = p.wy.data();
      const Real* __restrict wz = p.wz.data();
#pragma GCC ivdep
      for (int l = 0; l < kLaneWidth; ++l) {
        const std::uint32_t j = jj[l];
        L.wjx[l] = wx[j], L.wjy[l] = wy[j], L.wjz[l] = wz[j];
      }
    }
  }

  /// The first particles' values of the lanes (positions and velocities to xi ... vzi, radius, inverse
  /// mass and angular velocity to the lanes), eight lanes at a time: where the eight lie within eight
  /// consecutive owned particles (the rows of a settled pile hold 2-3 contacts each), one vector load of each
  /// array and a permutation (GCC's vector extensions: vpermpd); else one load per lane. The same values
  /// either way. Returns how many blocks of eight took the permutation (public: the tests count them).
 public:
  template <bool Rot, class Lanes>
  BASALT_WIDE_LANES static int first_ends(const Particles<Real>& p, const std::uint32_t* __restrict ii,
                                          Lanes& L, Real* __restrict xi, Real* __restrict yi,
                                          Real* __restrict zi, Real* __restrict vxi, Real* __restrict vyi,
                                          Real* __restrict vzi) {
    const Real* __restrict x = p.x.data();
    const Real* __restrict y = p.y.data();
    const Real* __restrict z = p.z.data();
    const Real* __restrict rad = p.radius.data();
    const Real* __restrict im = p.inv_mass.data();
    const Real* __restrict vx = p.vx.data();
    const Real* __restrict vy = p.vy.data();
    const Real* __restrict vz = p.vz.data();
    [[maybe_unused]] const Real* __restrict wx = Rot ? p.wx.data() : nullptr;
    [[maybe_unused]] const Real* __restrict wy = Rot ? p.wy.data() : nullptr;
    [[maybe_unused]] const Real* __restrict wz = Rot ? p.wz.data() : nullptr;
    constexpr int kBlock = 8;
    static_assert(kLaneWidth % kBlock == 0);
    using V = typename detail::Eight<Real>::V;
    using M = typename detail::Eight<Real>::M;
    using Index = typename detail::Eight<Real>::Index;
    int permuted = 0;
    for (int b = 0; b < kBlock * (kLaneWidth / kBlock); b += kBlock) {
      const std::uint32_t i0 = ii[b];
      // Lanes in row order: ii[b + 7] is the block's largest (a block out of order takes the loads). The
      // eight values read must lie within the owned particles' arrays.
      if (ii[b + kBlock - 1] - i0 < std::uint32_t(kBlock) && std::size_t(i0) + kBlock <= p.n_owned) {
        M at;
        bool ordered = true;
        for (int l = 0; l < kBlock; ++l) {
          at[l] = Index(ii[b + l] - i0);
          ordered = ordered && ii[b + l] - i0 < std::uint32_t(kBlock);
        }
        if (ordered) {
          const auto pick = [&](const Real* a, Real* out) {
            V v;
            std::memcpy(&v, a + i0, sizeof(V));
            v = __builtin_shuffle(v, at);
            std::memcpy(out + b, &v, sizeof(V));
          };
          pick(x, xi), pick(y, yi), pick(z, zi), pick(vx, vxi), pick(vy, vyi), pick(vz, vzi);
          pick(rad, L.ri), pick(im, L.imi);
          if constexpr (Rot) pick(wx, L.wix), pick(wy, L.wiy), pick(wz, L.wiz);
          ++permuted;
          continue;
        }
      }
#pragma GCC ivdep
      for (int l = b; l < b + kBlock; ++l) {
        const std::uint32_t i = ii[l];
        xi[l] = x[i], yi[l] = y[i], zi[l] = z[i], vxi[l] = vx[i], vyi[l] = vy[i], vzi[l] = vz[i];
        L.ri[l] = rad[i], L.imi[l] = im[i];
        if constexpr (Rot) L.wix[l] = wx[i], L.wiy[l] = wy[i], L.wiz[l] = wz[i];
      }
    }
    return permuted;
  }

 private:
  /// Each listed pair's row (its first particle), for the lanes' single loop over the pairs.
  static void row_of(const PairList& list, std::vector<std::uint32_t>& rows) {
    rows.resize(list.pairs());
    for (std::size_t i = 0; i + 1 < list.offset.size(); ++i)
      for (auto k = list.offset[i]; k < list.offset[i + 1]; ++k) rows[k] = static_cast<std::uint32_t>(i);
  }

  /// The pairs of `in` that pair compute `index` takes.
  static void filter(const PairLists<Real>& l, const PairList& in, std::size_t index, PairList& out) {
    const std::size_t n = in.offset.empty() ? 0 : in.offset.size() - 1;
    out.offset.assign(n + 1, 0);
    out.neigh.clear();
    out.bonded.clear();
    for (std::size_t i = 0; i < n; ++i) {
      for (auto k = in.offset[i]; k < in.offset[i + 1]; ++k)
        if (l.taker(i, static_cast<std::size_t>(in.neigh[k])) == static_cast<int>(index)) {
          out.neigh.push_back(in.neigh[k]);
          if (!in.bonded.empty()) out.bonded.push_back(in.bonded[k]);
        }
      out.offset[i + 1] = static_cast<std::uint32_t>(out.neigh.size());
    }
    out.index_loose();
  }

  /// The loops step over bonded pairs (they act by their bond): a history restored for one (a contact
  /// before its bond formed) is dropped here, as a parting contact's would be, its energy dissipated
  /// (models with a dissipation term, as the loops: a scalar law's too).
  void drop_bonded(const Particles<Real>& p, const PairList& list, std::vector<History>& hist, bool own) {
    if (list.bonded.empty()) return;
    for (std::size_t i = 0; i + 1 < list.offset.size(); ++i)
      for (auto e = list.offset[i]; e < list.offset[i + 1]; ++e) {
        if (list.bonded[e] == 0 || !holds(hist[e])) continue;
        const auto j = static_cast<std::size_t>(list.neigh[e]);
        if constexpr (kDissipates) {
          const int g = group_of(p.tag[i], p.tag[j]);
          if (g >= 0 && (own || p.id[i] < p.id[j]))
            dissipated_ += Model::parting_energy(coeffs_[static_cast<std::size_t>(g)], hist[e]);
        }
        Model::apart(hist[e]);
      }
  }

  static constexpr int kLaneWidth = kContactLaneWidth;
  /// The model decides when a pair interacts (models/contract.hpp, touching()).
  static constexpr bool kTouching = contract::HasTouching<Model, Real>;
  using Base::coeffs_, Base::params_, Base::pending_, Base::dissipated_, Base::sliding_, Base::dt_;
  using Base::kDissipates;
  static constexpr bool kLanes = requires(const Coeffs& c, ContactLanes<Real, kLaneWidth, History>& b) {
    Model::template contact_lanes<true>(c, b);
  };
  using Pass = LanePass<Real, Model, ContactLanes<Real, kLaneWidth, History>>;
  struct NoLanes {};
  [[no_unique_address]] std::conditional_t<kLanes, ContactLanes<Real, kLaneWidth, History>, NoLanes> lanes_{};
  std::vector<TagFilter> tags_;
  std::vector<std::string> names_;  ///< each group's name (reconfigure)
  bool uniform_ = false;
  const PairList* own_ = nullptr;
  const PairList* ghost_ = nullptr;
  PairList own_sub_, ghost_sub_;  ///< with several pair models: this model's share of the lists
  std::vector<History> hist_own_, hist_ghost_;
  std::vector<std::uint32_t> row_own_, row_ghost_;  ///< with lanes: each listed pair's row (row_of)
  const std::uint32_t* rows_ = nullptr;             ///< those of the list compute() loops over
};

}  // namespace basalt::solver
