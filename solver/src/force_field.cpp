#include "basalt/solver/interactions/force_field.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <string>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/models/registry.hpp"

namespace basalt::solver {

template <class Real>
ForceField<Real>::ForceField(const Scene& scene)
    : computes_(make_force_computes<Real>(scene)), walls_(scene.walls, scene.mesh_walls) {
  for (auto& c : computes_) {
    if (c->kind() == ModelKind::bond) bond_compute_ = c.get();
    if (c->kind() == ModelKind::pair) pair_computes_.push_back(c.get());
  }
  for (auto& c : computes_)  // pairs first, then walls: the order of the checkpoints' model index
    if (c->kind() == ModelKind::pair && c->history_bytes() > 0) history_computes_.push_back(c.get());
  for (auto& c : computes_)
    if (c->kind() == ModelKind::wall && c->history_bytes() > 0) history_computes_.push_back(c.get());
  for (const auto& g : scene.contacts) {
    std::size_t k = 0;
    while (pair_computes_[k]->model() != g.model) ++k;
    pair_group_tags_.push_back(g.tags);
    pair_group_compute_.push_back(static_cast<int>(k));
  }
  pairs_take_all_ = scene.contacts.size() == 1 && scene.contacts[0].tags.empty();
  const char* rebuild_on_break = std::getenv("BASALT_REBUILD_ON_BREAK");
  mark_bonds_ = pair_computes_.size() == 1 && bonds_can_break() &&
                !(rebuild_on_break && std::string(rebuild_on_break) == "1");
  // Checkpoints store all contact histories in one table as wide as the widest history; narrower ones
  // are padded with zeros (SimulationFrame) and read back at their own width (restart).

  // The ledger: every scene has the standard terms (a saver of one nothing fills saves zeros); body
  // forces add theirs.
  for (const auto& name : standard_energy_terms())
    ledger_.add(name, name == "kinetic_energy" ? Ledger::Kind::kinetic
                      : name == "wall_work_in" ? Ledger::Kind::work
                                               : Ledger::Kind::potential);
  kinetic_term_ = static_cast<std::size_t>(ledger_.find("kinetic_energy"));
  wall_work_term_ = static_cast<std::size_t>(ledger_.find("wall_work_in"));
  for (const auto& c : computes_)
    compute_term_.push_back(
        c->energy_term().empty() ? kNoTerm : ledger_.add(c->energy_term(), Ledger::Kind::potential));
  for (std::size_t k = 0; k < computes_.size(); ++k) {
    computes_[k]->set_time_step(scene.dt);
    const auto term = computes_[k]->dissipation_term();
    if (!term.empty()) dissipation_.emplace_back(ledger_.add(term, Ledger::Kind::dissipated), k);
  }
  // A compute without a potential (damping) adds its zero to a slot past the ledger's terms.
  for (auto& t : compute_term_)
    if (t == kNoTerm) t = ledger_.size();
  body_term_.assign(ledger_.size() + 1, 0);
  for (std::size_t k = 0; k < computes_.size(); ++k)
    if (computes_[k]->kind() == ModelKind::body && compute_term_[k] < ledger_.size())
      body_term_[compute_term_[k]] = 1;
  pe_.assign(ledger_.size() + 1, 0.0);
  for (std::size_t k = 0; k < scene.fields.size(); ++k) {
    const auto& f = scene.fields[k];
    if (f.type == FieldSpec::Type::energy && ledger_.find(f.term) < 0)
      throw InputError(fmt::format(
          "output.fields[{}]: type = \"{}\": no model of this scene has that energy term (add the body force "
          "that owns it)",
          k, f.term));
  }
}

template <class Real>
double ForceField<Real>::dissipated(std::size_t t) const {
  double d = 0;
  for (const auto& [term, k] : dissipation_)
    if (term == t) d += computes_[k]->dissipated();
  return d;
}

template <class Real>
double ForceField<Real>::max_stiffness(double rmax) const {
  double k = 0;
  for (const auto& c : computes_) k = std::max(k, c->max_stiffness(rmax));
  return k;
}

template <class Real>
double ForceField<Real>::pair_reach(double rmax) const {
  double r = 0;
  for (const auto* c : pair_computes_) r = std::max(r, c->reach(rmax));
  return r;
}

template <class Real>
int ForceField<Real>::pair_taker(std::int64_t ti, std::int64_t tj) const {
  for (std::size_t g = 0; g < pair_group_tags_.size(); ++g) {
    const auto& t = pair_group_tags_[g];
    if (t.empty() || (t[0] == ti && t[1] == tj) || (t[0] == tj && t[1] == ti)) return pair_group_compute_[g];
  }
  return -1;
}

template <class Real>
std::vector<ContactRecords*> ForceField<Real>::pending_history() const {
  std::vector<ContactRecords*> r;
  for (auto* c : history_computes_) r.push_back(c->pending());
  return r;
}

template <class Real>
void ForceField<Real>::rebuild_lists(const Particles<Real>& p,
                                     const std::vector<std::uint32_t>& bond_bucket_end,
                                     const Bonds<Real>& bonds, double skin, double contact_cutoff) {
  if (!pair_computes_.empty()) {
    // Cells half the longest cutoff: each particle searches only as far as it can reach (a third or a
    // quarter measured slower on the 30 mm cube: more rows to step through).
    grid_.size_to(p.x, p.y, p.z, p.size(), contact_cutoff / 2);
    grid_.fill(p.x, p.y, p.z, 0, p.n_owned);
    ghost_grid_.size_like(grid_);
    ghost_grid_.fill(p.x, p.y, p.z, p.n_owned, p.size());
    exclusions_.bind(bond_bucket_end, bonds.ib, p.n_owned);
    const auto taker = [&](std::size_t i, std::size_t j) { return pair_taker(p.tag[i], p.tag[j]); };
    // The lists keep pairs closer than ri + rj + reach + skin, the reach of the largest radius here
    // (owned and ghosts): every pair that can interact before the next rebuild. 0 for contact by overlap.
    double margin = skin;
    if (pair_reach(1.0) > 0) {  // (scenes without a cohesive model skip the pass)
      double rmax = 0;
      for (std::size_t i = 0; i < p.size(); ++i) rmax = std::max(rmax, double(p.radius[i]));
      margin = skin + pair_reach(rmax);
    }
    if (pairs_take_all_) {
      build_pair_lists(
          p, grid_, ghost_grid_, margin, exclusions_, [](std::size_t, std::size_t) { return true; }, own_,
          ghost_, mark_bonds_);
    } else {
      build_pair_lists(
          p, grid_, ghost_grid_, margin, exclusions_,
          [&](std::size_t i, std::size_t j) { return taker(i, j) >= 0; }, own_, ghost_, mark_bonds_);
    }
    const PairLists<Real> lists{p, own_, ghost_, pair_computes_.size(), taker};
    for (std::size_t k = 0; k < pair_computes_.size(); ++k) pair_computes_[k]->rebuild(lists, k);
    grid_.release();
    ghost_grid_.release();
  }
  if (!walls_.empty()) {
    walls_.rebuild(p, skin);
    for (auto& c : computes_)
      if (c->kind() == ModelKind::wall) c->rebuild_walls(p, walls_);
  }
}

template <class Real>
std::size_t ForceField<Real>::memory_bytes() const {
  std::size_t b = own_.memory_bytes() + ghost_.memory_bytes() + walls_.memory_bytes();
  for (const auto& c : computes_) b += c->memory_bytes();
  return b;
}

template class ForceField<double>;
template class ForceField<float>;

}  // namespace basalt::solver
