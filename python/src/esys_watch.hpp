#pragma once
// ESyS-Particle's neighbour-list rule and spatial domain, watched after every step for the ESyS front end
// (python/basalt/esys/lsmmpi.py), so that a run with checkpointers need not stop at every step to gather the
// positions in Python.
//
// The rule (ESyS's TSubLattice::checkNeighbors, measured in docs/esys.md): as a step begins, when a particle
// has moved more than verletDist/2 since the last rebuild, every particle's "position at the last rebuild"
// becomes its current one. A checkpoint written after step n shows the rule applied to the positions after
// step n - 1: so the positions a check after step n finds are held back (pending) and become the reference
// at the next check. The domain: ESyS removes the particles outside its grown spatial domain at a rebuild
// (measured: a particle crossing it is listed until the step whose positions trigger the next rebuild, and
// gone from the step after), so a check that finds a rebuild due while a particle is outside ends the run
// after that step: the front end writes that step's output, deletes the particle and resets the reference.
//
// Collective: every rank keeps every particle's reference (ids sorted, three coordinates each); a check is
// two reductions, and a rebuild one all_gather of the positions.
#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/parallel/communicator.hpp"

namespace basalt::python {

template <class Real>
class EsysWatch {
 public:
  /// limit2: (verletDist / 2)^2; lo, hi: the grown spatial domain.
  EsysWatch(double limit2, std::array<double, 3> lo, std::array<double, 3> hi)
      : limit2_(limit2), lo_(lo), hi_(hi) {}

  /// Collective: every particle's current position becomes its reference (at the start, after deletions).
  void reset(const solver::Particles<Real>& p, const solver::Comm& comm) {
    positions(p, comm, ids_, ref_);
    index();
    pending_ = false;
  }

  /// Collective, after each step: the held-back rebuild taken, the rule checked on the current positions,
  /// the domain checked. False when a rebuild is due and a particle is outside the domain (the run stops
  /// after this step).
  bool check(const solver::Particles<Real>& p, const solver::Comm& comm) {
    if (pending_) {
      std::swap(ids_, next_ids_);
      std::swap(ref_, next_ref_);
      index();
      pending_ = false;
    }
    double moved2 = 0, outside = 0;
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      const double x = double(p.x[i]), y = double(p.y[i]), z = double(p.z[i]);
      if (x < lo_[0] || x > hi_[0] || y < lo_[1] || y > hi_[1] || z < lo_[2] || z > hi_[2]) outside = 1;
      const std::size_t k = slot(p.id[i]);
      if (k == kNone) {  // a particle the reference does not hold: a rebuild, as for a changed count
        moved2 = std::numeric_limits<double>::infinity();
        continue;
      }
      const double dx = x - ref_[3 * k], dy = y - ref_[3 * k + 1], dz = z - ref_[3 * k + 2];
      moved2 = std::max(moved2, (dx * dx + dy * dy) + dz * dz);  // numpy's order: ((dx² + dy²) + dz²)
    }
    if (comm.size() > 1) {
      moved2 = comm.max(moved2);
      outside = comm.max(outside);
    }
    if (moved2 > limit2_) {
      positions(p, comm, next_ids_, next_ref_);
      pending_ = true;
    }
    return !(pending_ && outside != 0);
  }

  /// Collective: the boxes beyond the domain's sides that particles lie past now (one per side, in the order
  /// x below, x above, y below, ... ; each reaching 1e30 beyond the domain): ESyS removes those particles at
  /// its rebuild, all at once.
  std::vector<std::array<std::array<double, 3>, 2>> outside_boxes(const solver::Particles<Real>& p,
                                                                  const solver::Comm& comm) const {
    constexpr double kFar = 1e30;
    std::vector<std::array<std::array<double, 3>, 2>> boxes;
    for (std::size_t k = 0; k < 3; ++k) {
      const auto& c = k == 0 ? p.x : k == 1 ? p.y : p.z;
      double below = 0, above = 0;
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        if (double(c[i]) < lo_[k]) below = 1;
        if (double(c[i]) > hi_[k]) above = 1;
      }
      if (comm.size() > 1) {
        below = comm.max(below);
        above = comm.max(above);
      }
      for (const bool low : {true, false}) {
        if ((low ? below : above) == 0) continue;
        std::array<std::array<double, 3>, 2> box = {{{-kFar, -kFar, -kFar}, {kFar, kFar, kFar}}};
        if (low) {
          box[1][k] = lo_[k];
        } else {
          box[0][k] = hi_[k];
        }
        boxes.push_back(box);
      }
    }
    return boxes;
  }

  /// A rebuild found due by the last check, taken at the next one (or by reset()).
  bool rebuild_due() const { return pending_; }

  /// The references in id order: ids and 3 coordinates each.
  const std::vector<std::int64_t>& ids() const { return ids_; }
  const std::vector<double>& reference() const { return ref_; }

 private:
  static constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

  /// Every rank's particles' (id, x, y, z), sorted by id, on every rank.
  static void positions(const solver::Particles<Real>& p, const solver::Comm& comm,
                        std::vector<std::int64_t>& ids, std::vector<double>& xyz) {
    std::vector<double> mine;
    mine.reserve(4 * p.n_owned);
    for (std::size_t i = 0; i < p.n_owned; ++i)
      mine.insert(mine.end(), {double(p.id[i]), double(p.x[i]), double(p.y[i]), double(p.z[i])});
    const std::vector<double> all = comm.size() > 1 ? comm.all_gather(mine) : mine;
    const std::size_t n = all.size() / 4;
    std::vector<std::size_t> order(n);
    for (std::size_t k = 0; k < n; ++k) order[k] = k;
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return all[4 * a] < all[4 * b]; });
    ids.resize(n);
    xyz.resize(3 * n);
    for (std::size_t k = 0; k < n; ++k) {
      ids[k] = static_cast<std::int64_t>(all[4 * order[k]]);
      for (int c = 0; c < 3; ++c) xyz[3 * k + c] = all[4 * order[k] + 1 + c];
    }
  }

  /// The slot of each id: a table over the ids' range when they are dense (ESyS scripts number from 0),
  /// else a binary search.
  void index() {
    dense_.clear();
    if (ids_.empty()) return;
    const std::int64_t span = ids_.back() - ids_.front() + 1;
    if (span > 4 * static_cast<std::int64_t>(ids_.size()) + 1024) return;
    dense_.assign(static_cast<std::size_t>(span), kNone);
    for (std::size_t k = 0; k < ids_.size(); ++k)
      dense_[static_cast<std::size_t>(ids_[k] - ids_.front())] = k;
  }
  std::size_t slot(std::int64_t id) const {
    if (ids_.empty() || id < ids_.front() || id > ids_.back()) return kNone;
    if (!dense_.empty()) return dense_[static_cast<std::size_t>(id - ids_.front())];
    const auto it = std::lower_bound(ids_.begin(), ids_.end(), id);
    return it != ids_.end() && *it == id ? static_cast<std::size_t>(it - ids_.begin()) : kNone;
  }

  double limit2_;
  std::array<double, 3> lo_, hi_;
  std::vector<std::int64_t> ids_, next_ids_;
  std::vector<double> ref_, next_ref_;
  std::vector<std::size_t> dense_;
  bool pending_ = false;
};

}  // namespace basalt::python
