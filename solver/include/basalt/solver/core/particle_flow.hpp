#pragma once
// Particles entering and leaving the run (scene/flow_spec.hpp, docs/scenes.md "Insertion and deletion"):
// the queue of inserts and deletes for the next rebuild, the id counter of inserted particles, the largest
// radius the lists reach, and the counts. Both happen at a rebuild (Simulation::rebuild, simulation_flow.cpp
// for the callers' side). Insertion draws its candidates alike on every rank (core/particle_source.hpp), lets
// the rank owning each candidate's place say whether an existing particle (owned or ghost) blocks it, agrees
// on that, and takes the same candidates everywhere with ids from one counter (kept in checkpoints): ids stay
// unique and the inserted set does not depend on the ranks. Deletion removes the owned particles of the
// region and, on every rank, the bonds to them. Collective parts take the decomposition (its Comm).
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "basalt/solver/core/bonds.hpp"
#include "basalt/solver/core/particle_source.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/parallel/decomposition.hpp"
#include "basalt/solver/parallel/geometry_loader.hpp"
#include "basalt/solver/scene/flow_spec.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::solver {

template <class Real>
class ParticleFlow {
 public:
  /// Fresh start: the scene's [[insert]] regions and radii into the decomposition's box and the lists'
  /// reach `e`; the largest radius and the next id from it.
  void include(const Scene& scene, GeometryExtent& e);
  /// Restart: the next id from the checkpoint's attribute next_particle_id (else last_id + 1), the lists'
  /// reach from the largest radius rmax and the scene's [[insert]]s.
  void restore(const Scene& scene, const std::map<std::string, std::string>& attributes, std::int64_t last_id,
               double rmax);

  /// Queues the scene's insert and delete events of step s (the one about to be made); whether any is.
  bool queue(const Scene& scene, std::int64_t s);
  /// Queues a caller's insert (its region in the run's frame) or deletion for the next rebuild.
  void queue(InsertSpec spec) { queue_.inserts.push_back(std::move(spec)); }
  void queue(DeleteSpec spec) { queue_.deletes.push_back(std::move(spec)); }
  /// Whether inserts or deletions wait for the next rebuild.
  bool pending() const { return !queue_.inserts.empty() || !queue_.deletes.empty(); }
  /// InputError when spec's particles do not fit the run: a radius beyond the lists' reach, or (unless
  /// forced) lighter than the run's lightest m_min by so much that dt exceeds their contacts' critical step
  /// (dt_critical scaled by sqrt(m / m_min)).
  void check_insert(const InsertSpec& spec, double dt, double m_min, double dt_critical, bool forced) const;

  /// Collective, at a rebuild, before the ghosts go: the queued inserts' particles, chosen alike on every
  /// rank where nothing (owned or ghost, of `p`) blocks them, with their ids.
  void plan_arrivals(const Particles<Real>& p, const Decomposition& dec, std::int64_t step);
  /// Collective, at a rebuild, after the ghosts went: removes the queued deletions' owned particles and
  /// (every rank) their bonds, appends the arrivals this rank owns, counts (last()); empties the queue.
  void exchange(Particles<Real>& p, Bonds<Real>& bonds, const Decomposition& dec);

  /// Inserted, removed by the last exchange.
  const std::array<std::int64_t, 2>& last() const { return last_; }
  /// Inserted, removed since the start of this process's run.
  const std::array<std::int64_t, 2>& totals() const { return totals_; }
  /// The id the next inserted particle gets (alike on every rank).
  std::int64_t next_id() const { return next_id_; }
  /// Inserted ids were issued (or a checkpoint kept the counter): checkpoints keep next_id().
  bool ids_issued() const { return ids_issued_; }
  /// The largest radius the lists reach (the geometry's and the scene's [[insert]]s').
  double rmax() const { return rmax_; }
  /// Particles came or went at a rebuild since settled(): the energy guard takes a new reference.
  bool changed() const { return changed_; }
  void settled() { changed_ = false; }

 private:
  /// Particles to insert and remove at the next rebuild (the scene's events due, or a caller's), and the
  /// inserts' chosen particles.
  struct Queue {
    std::vector<InsertSpec> inserts;
    std::vector<DeleteSpec> deletes;
    std::vector<NewParticle> arriving;
  } queue_;
  std::int64_t next_id_ = 0;
  double rmax_ = 0;
  std::array<std::int64_t, 2> last_{0, 0};
  std::array<std::int64_t, 2> totals_{0, 0};
  bool changed_ = false;
  bool ids_issued_ = false;
};

extern template class ParticleFlow<double>;
extern template class ParticleFlow<float>;

}  // namespace basalt::solver
