#pragma once
// The scene's interactions on one rank: one force compute per model the scene uses (built through the
// registry, models/registry.hpp), the walls they act through, the contact candidate lists they share,
// and the energy ledger their potentials fill. Simulation drives it: rebuild_lists() at each
// neighbour-list rebuild, add() twice per step (owned part, then ghost part).
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "basalt/solver/core/bonds.hpp"
#include "basalt/solver/core/ledger.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/interactions/force_compute.hpp"
#include "basalt/solver/interactions/walls.hpp"
#include "basalt/solver/neighbor/cell_grid.hpp"
#include "basalt/solver/neighbor/verlet_list.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/timers.hpp"

namespace basalt::solver {

template <class Real>
class ForceField {
 public:
  /// Builds the computes and the ledger; throws InputError for a field saver of a term nothing fills or
  /// a combination of models not supported.
  explicit ForceField(const Scene& scene);

  const std::vector<std::unique_ptr<ForceCompute<Real>>>& computes() const { return computes_; }
  const std::vector<ForceCompute<Real>*>& pair_computes() const { return pair_computes_; }
  /// The computes that keep contact history (pair models, then wall models): a checkpoint's contact
  /// model index counts these.
  const std::vector<ForceCompute<Real>*>& history_computes() const { return history_computes_; }
  bool has_pairs() const { return !pair_computes_.empty(); }
  /// How far beyond ri + rj the scene's pair models reach for particles up to radius rmax (0 for
  /// contact by overlap): the pair lists, ghosts and cells grow by it.
  double pair_reach(double rmax) const;
  /// Whether a pair model reads velocities (then ghosts carry them, Particles::ghost_velocity).
  bool needs_ghost_velocity() const {
    for (const auto* c : pair_computes_)
      if (c->reads() & kVelocity) return true;
    return false;
  }
  /// Largest spring constant over the models for radii up to rmax.
  double max_stiffness(double rmax) const;
  /// Rest length of a new bond of group g (the bond model's rule); r without bond models.
  double rest_length(std::size_t g, double ri, double rj, double r) const {
    return bond_compute_ ? bond_compute_->rest_length(g, ri, rj, r) : r;
  }
  /// Whether a bond model turns with its particles (rotational bonds: Particles::with_bond_frame).
  bool needs_bond_frame() const { return bond_compute_ && (bond_compute_->reads() & kOrientation); }
  /// Whether some bond can break (the scene then keeps each particle's bond damage).
  bool bonds_can_break() const { return bond_compute_ && bond_compute_->can_break(); }
  Walls& walls() { return walls_; }
  const Walls& walls() const { return walls_; }
  const PairList& own_pairs() const { return own_; }
  const PairList& ghost_pairs() const { return ghost_; }
  /// Whether the contact lists hold bonded pairs, marked (bonds can break and one pair model takes
  /// every contact): a broken bond's pair then becomes a contact through unbond(), without a rebuild.
  /// BASALT_REBUILD_ON_BREAK=1 turns it off (bonded pairs excluded, a break forces a rebuild: the
  /// measurement of what it saves, and the test that both give the same forces).
  bool lists_mark_bonds() const { return mark_bonds_; }
  /// The bonds of these pairs (local ends, as Bonds::parted) broke: their listed pairs are contacts now.
  void unbond(const std::vector<std::array<std::int32_t, 2>>& pairs) {
    for (const auto& [i, j] : pairs)
      for (PairList* list : {&own_, &ghost_})
        list->unbond(static_cast<std::size_t>(i), static_cast<std::size_t>(j));
  }
  /// The bonded marks of both lists (to undo the breaks of a trial force computation).
  std::array<std::vector<std::uint8_t>, 2> bond_marks() const { return {own_.bonded, ghost_.bonded}; }
  void set_bond_marks(std::array<std::vector<std::uint8_t>, 2> marks) {
    own_.bonded = std::move(marks[0]);
    ghost_.bonded = std::move(marks[1]);
    own_.index_loose();
    ghost_.index_loose();
  }

  // Energy ledger.
  const Ledger& ledger() const { return ledger_; }
  std::size_t kinetic_term() const { return kinetic_term_; }
  std::size_t wall_work_term() const { return wall_work_term_; }
  /// This rank's energy dissipated so far into ledger term t (of kind dissipated).
  double dissipated(std::size_t t) const;
  /// Whether ledger term t is a body force's potential.
  bool body_term(std::size_t t) const { return body_term_[t] != 0; }
  /// This rank's potentials by ledger term, from the last add() with energy since zero_energies().
  const std::vector<double>& potentials() const { return pe_; }
  void zero_energies() { std::fill(pe_.begin(), pe_.end(), 0.0); }

  /// Adds the forces of one part (Part::owned, then Part::ghost) and, with `energy`, the potentials.
  /// In the owned part `poke()` is called once between the bond models and the others (the ghost
  /// refresh in flight moves along while pairs are computed).
  /// Each compute's time goes to its model kind (kind_seconds()); the poke's to none.
  template <class Poke>
  void add(ForceState<Real>& s, Part part, bool energy, bool advance, Poke&& poke) {
    bool poked = part != Part::owned;
    Stopwatch sw;
    for (std::size_t k = 0; k < computes_.size(); ++k) {
      if (!poked && computes_[k]->kind() != ModelKind::bond) {
        poke();
        poked = true;
        sw.lap();
      }
      pe_[compute_term_[k]] += computes_[k]->compute(s, part, energy, advance);
      kind_seconds_[static_cast<std::size_t>(computes_[k]->kind())] += sw.lap();
    }
  }
  /// Seconds spent in add() by the computes of each model kind (indexed by ModelKind: bond, pair, wall,
  /// body), summed since construction: what basalt-run's "forces by model kind" line reports.
  const std::array<double, 4>& kind_seconds() const { return kind_seconds_; }

  // Rebuilds.
  /// Before a rebuild (ghosts still present): contact histories into the pending records.
  void save_history(const Particles<Real>& p) {
    for (auto* c : history_computes_) c->save_history(p);
  }
  /// The pending records of each pair compute (null: no history), for migration and restarts.
  std::vector<ContactRecords*> pending_history() const;
  /// After migration, ghosts and bonds: the contact lists (bonded pairs excluded through the bonds'
  /// buckets, see Exclusions, or listed and marked: lists_mark_bonds()), each pair model's share with its
  /// history, the walls' candidates.
  void rebuild_lists(const Particles<Real>& p, const std::vector<std::uint32_t>& bond_bucket_end,
                     const Bonds<Real>& bonds, double skin, double contact_cutoff);

  std::size_t memory_bytes() const;

 private:
  /// The pair compute taking a pair with these tags (first pair group that takes them), or -1.
  int pair_taker(std::int64_t ti, std::int64_t tj) const;

  std::vector<std::unique_ptr<ForceCompute<Real>>> computes_;
  ForceCompute<Real>* bond_compute_ = nullptr;
  std::vector<ForceCompute<Real>*> pair_computes_;
  std::vector<ForceCompute<Real>*> history_computes_;
  std::vector<TagFilter> pair_group_tags_;  ///< each scene pair group's tags
  std::vector<int> pair_group_compute_;     ///< each scene pair group's compute in pair_computes_
  bool pairs_take_all_ = false;             ///< one pair group, every tag
  bool mark_bonds_ = false;                 ///< lists_mark_bonds()
  Walls walls_;
  PairList own_, ghost_;
  CellGrid grid_, ghost_grid_;  ///< owned and ghost particles in the same cells (rebuilds only)
  Exclusions exclusions_;
  Ledger ledger_;
  std::vector<std::size_t> compute_term_;  ///< the ledger term of each compute's potential
  std::array<double, 4> kind_seconds_{};   ///< kind_seconds()
  std::size_t kinetic_term_ = 0, wall_work_term_ = 0;
  static constexpr std::size_t kNoTerm = std::size_t(-1);
  std::vector<char> body_term_;
  std::vector<std::pair<std::size_t, std::size_t>> dissipation_;  ///< (ledger term, compute) pairs
  std::vector<double> pe_;
};

extern template class ForceField<double>;
extern template class ForceField<float>;

}  // namespace basalt::solver
