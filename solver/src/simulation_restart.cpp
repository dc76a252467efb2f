// Continuing a run from a checkpoint: the same decomposition (box, ghost width and contact cut-off
// stored with the checkpoint), particles with their velocities and exact inverse masses, bonds with
// their rest lengths, the clock. Every rebuild is canonical (its result is a function of the owned
// (id, position) sets), so replaying the uninterrupted run's last rebuild from the positions it
// used (stored in the checkpoint) gives the same lists, ghosts and summation order: on the same
// ranks both runs continue bit for bit, and the uninterrupted run needs no extra rebuild.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/parallel/checkpoint_loader.hpp"
#include "basalt/solver/scene/load_checks.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
void Simulation<Real>::begin_restart(std::size_t particles, double dt, const RestartLayout& layout) {
  configure_particles();
  if (mixed_) {  // the frame of the run that wrote the checkpoint (frame_origin.hpp)
    origin_ = layout.origin;
    enter_frame();
  }
  if (particles == 0) throw InputError("the checkpoint has no particles");
  if (scene_.bonds.size() > 254) throw InputError("interactions: at most 254 bond groups");
  const double scene_dt = scene_.dt;
  if (scene_.dt_fraction > 0) scene_.dt = dt;  // the run's dt (a fraction of the critical step at its start)
  if (dt != scene_.dt)
    throw InputError(
        fmt::format("the checkpoint was written with dt = {}, the scene has run.dt = {}", dt, scene_dt));
  apply_dt(scene_.clock_base.dt > 0 ? scene_.clock_base.dt : scene_.dt);
  // (a staged run's dt change, replayed: stages.hpp)
  clock_.set_base(scene_.clock_base.step, scene_.clock_base.time);
  schedule_.configure(scene_.skin);
}

template <class Real>
Simulation<Real>::Simulation(const Scene& scene, const io::Checkpoint& c, const RestartLayout& layout,
                             MPI_Comm comm, const RunOptions& options)
    : scene_(scene), options_(options), forces_(scene) {
  begin_restart(c.size(), c.dt, layout);
  const bool replay = !c.position_at_rebuild.empty();
  auto summary = summarize_geometry(scene_, c.geometry, "the checkpoint");
  if (mixed_) summary.xmax = frame_xmax(CheckpointFrame(c, origin_), c.size());
  run_load_checks(scene_, summary, "the checkpoint", comm, kEpsilon, precision_name());
  check_stability(summary);
  check_checkpoint_rows(c, replay);
  restore_decomposition(layout, comm);
  n_global_ = static_cast<std::int64_t>(c.size());
  ids_.configure(c.geometry.id.front(), c.geometry.id.back(), c.size());
  flow_.restore(scene_, c.geometry.attributes, c.geometry.id.back(), summary.rmax);
  distribute_checkpoint(c, nullptr, replay);
  finish_restart(c, replay);
}

template <class Real>
Simulation<Real>::Simulation(const Scene& scene, const io::CheckpointFile& file, const RestartLayout& layout,
                             MPI_Comm comm, const RunOptions& options)
    : scene_(scene), options_(options), forces_(scene) {
  const auto& h = file.header();
  begin_restart(h.particles, h.run.dt, layout);
  const bool replay = h.has_position_at_rebuild;
  const Comm all(comm);
  CheckpointLoader loader(file, all);
  // The checks see the whole checkpoint through the slices' summaries (mins, maxima and tag sets are exact).
  auto local = summarize_geometry(scene_, loader.slice().geometry, "the checkpoint");
  if (mixed_) local.xmax = frame_xmax(CheckpointFrame(loader.slice(), origin_), loader.slice().size());
  const auto summary = merge_summaries(local, comm);
  run_load_checks(scene_, summary, "the checkpoint", comm, kEpsilon, precision_name());
  check_stability(summary);
  {  // the lowest rank's first bad row is the file's first
    std::optional<std::string> error;
    try {
      check_checkpoint_rows(loader.slice(), replay);
    } catch (const std::exception& e) {
      error = e.what();
    }
    if (auto e = all.agree_error(error)) throw InputError(*e);
  }
  restore_decomposition(layout, comm);
  load_stats_.particle_rows = loader.slice().size();
  load_stats_.bond_rows = loader.slice().geometry.bonds.size();
  n_global_ = static_cast<std::int64_t>(h.particles);
  ids_.configure(loader.first_id(), loader.last_id(), h.particles);
  flow_.restore(scene_, h.run.geometry.attributes, loader.last_id(), summary.rmax);
  CheckpointPart part = loader.local_part(*dec_, origin_);
  load_stats_.owned = part.c.size();
  load_stats_.bonds = part.c.geometry.bonds.size();
  distribute_checkpoint(part.c, &part.bond_length, replay);
  finish_restart(part.c, replay);
}

template <class Real>
void Simulation<Real>::finish_restart(const io::Checkpoint& c, bool replay) {
  restore_servos(c, replay);
  if (replay) {
    replay_rebuild(c);
  } else {
    if (dec_->comm().rank() == 0)
      fmt::print(stderr,
                 "basalt-run: warning: the checkpoint has no /particles/position_at_rebuild (written by an "
                 "older basalt-run): the lists are rebuilt at step {}, so the continuation agrees with the "
                 "uninterrupted run to rounding only\n",
                 clock_.step());
    if (!forces_.walls().empty()) forces_.walls().move_to(time_at(clock_.step()));
    rebuild();
  }
  balancer_.set_paused(false);
  check_start(false);
  estimate_critical_step(false);  // simulation_stability.cpp
  guard_.start(forces_.ledger(), ledger_totals(compute_forces<true>()));
  restore_kick_forces(c);  // simulation_kick_forces.cpp
}

template <class Real>
void Simulation<Real>::check_checkpoint_rows(const io::Checkpoint& c, bool replay) {
  const auto& g = c.geometry;
  for (std::size_t k = 0; k < g.bonds.size(); ++k) {
    const auto& b = g.bonds[k];
    const int state = c.bond_broken[k] & 3;
    if (state == 1 || (state == 2 && !replay)) continue;  // kept on record only
    if (b.tag < 0 || static_cast<std::size_t>(b.tag) >= scene_.bonds.size())
      throw InputError(
          fmt::format("the checkpoint's bond {}-{} belongs to interaction group {}, but the scene has "
                      "{} bond group(s)",
                      b.a, b.b, b.tag, scene_.bonds.size()));
  }
  // The table is as wide as the widest model's history; each model reads its own width from the front.
  std::size_t models = 0, widest = 0;
  for (auto* pc : forces_.history_computes())
    if (pc->pending()) {
      ++models;
      widest = std::max(widest, pc->pending()->width);
    }
  for (std::size_t k = 0; k < c.contact_ids.size(); ++k) {
    const auto model = static_cast<std::size_t>(c.contact_model[k]);
    if (model >= models || c.contact_width != widest)
      throw InputError(fmt::format(
          "the checkpoint's contact {}-{} has a history of {} values for contact model {}, but the scene's "
          "contact models with history are {} (histories of up to {} values)",
          c.contact_ids[k][0], c.contact_ids[k][1], c.contact_width, model, models, widest));
  }
}

template <class Real>
void Simulation<Real>::restore_decomposition(const RestartLayout& layout, MPI_Comm comm) {
  dec_ = std::make_unique<Decomposition>(Comm(comm), options_.dims, layout.box_min, layout.box_max);
  // The checkpoint's cuts when they fit this rank grid (the same ranks along each axis): the replayed
  // rebuild then finds every particle where the run had it and must not move them (the balancer paused).
  // On another grid the cuts start even and a balanced run re-balances at that rebuild.
  bool fits = true;
  for (int d = 0; d < 3; ++d)
    fits = fits &&
           layout.cuts[static_cast<std::size_t>(d)].size() == static_cast<std::size_t>(dec_->dims()[d] - 1);
  if (fits && !(layout.cuts[0].empty() && layout.cuts[1].empty() && layout.cuts[2].empty())) {
    dec_->set_cuts(layout.cuts);
    balancer_.set_paused(true);
  }
  halo_ = std::make_unique<Halo<Real>>(*dec_);
  ghost_width_ = layout.ghost_width;
  contact_cutoff_ = layout.contact_cutoff;
  if (dec_->min_interior_width() < ghost_width_)
    throw InputError(fmt::format(
        "too many ranks for this geometry: a rank's region would be {:.4g} wide, less than the ghost width "
        "{:.4g} (longest interaction + skin); use fewer ranks or other --dims (now {}x{}x{})",
        dec_->min_interior_width(), ghost_width_, dec_->dims()[0], dec_->dims()[1], dec_->dims()[2]));
}

template <class Real>
void Simulation<Real>::distribute_checkpoint(const io::Checkpoint& c, const std::vector<double>* bond_length,
                                             bool replay) {
  const auto& g = c.geometry;
  // Particles go where the last rebuild's migration put them: by their positions at that rebuild
  // (replay_rebuild restores the current ones), or by the current ones for an old checkpoint.
  const bool at_rebuild = !c.position_at_rebuild.empty();
  const CheckpointFrame frame(c, origin_);  // positions in the run's frame (mixed precision)
  std::vector<char> owned(g.size(), 0);
  std::vector<std::size_t> mine;  // geometry index of each owned particle, in local order
  for (std::size_t i = 0; i < g.size(); ++i) {
    const auto x = frame.position(i, at_rebuild);
    if (!dec_->owns(x[0], x[1], x[2])) continue;
    owned[i] = 1;
    mine.push_back(i);
    const double im = c.inv_mass.empty() ? 1.0 / g.mass[i] : c.inv_mass[i];
    const auto& v = c.velocity[i];
    p_.push_owned(g.id[i], Real(x[0]), Real(x[1]), Real(x[2]), Real(g.radius[i]), g.tag[i], Real(im),
                  Real(v[0]), Real(v[1]), Real(v[2]));
  }
  // A part of a checkpoint holds the owned particles only: an id it lacks is not owned.
  const auto is_owned = [&](std::int64_t id) {
    const auto i = g.index_of(id);
    return i >= 0 && owned[static_cast<std::size_t>(i)] != 0;
  };
  // A bond that broke at the checkpoint's own step (flag 2) is restored intact when the rebuild is
  // replayed: the uninterrupted run's lists, built before it broke, excluded its pair from contacts,
  // and the restart's first force computation breaks it again from the same positions.
  restore_particle_fields(c, mine, replay);
  constexpr double unknown = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 0, nb = 0; k < g.bonds.size(); ++k) {
    const auto& b = g.bonds[k];
    // Where it broke: the checkpoint's row for it among its broken bonds (NaN when it has none).
    const io::Vec3 where = c.bond_broken[k] == 0 || c.bond_break_position.empty()
                               ? io::Vec3{unknown, unknown, unknown}
                               : frame.point(c.bond_break_position[nb]);
    nb += c.bond_broken[k] != 0 ? 1 : 0;
    const int state = c.bond_broken[k] & 3;
    if (state == 1 || (state == 2 && !replay)) {
      // Kept on record (once, by the rank owning the lower id) so later checkpoints still list it.
      if (is_owned(std::min(b.a, b.b))) {
        double len = 0;
        if (bond_length) {
          len = (*bond_length)[k];
        } else {
          const auto& pa = g.position[static_cast<std::size_t>(g.index_of(b.a))];
          const auto& pb = g.position[static_cast<std::size_t>(g.index_of(b.b))];
          len = std::sqrt((pa[0] - pb[0]) * (pa[0] - pb[0]) + (pa[1] - pb[1]) * (pa[1] - pb[1]) +
                          (pa[2] - pb[2]) * (pa[2] - pb[2]));
        }
        BrokenBond r{b.a, b.b, len, c.bond_rest_length[k]};
        r.mode = static_cast<std::uint8_t>(c.bond_broken[k] >> 2);
        r.x = where[0];
        r.y = where[1];
        r.z = where[2];
        broken_.push_back(r);
      }
      continue;
    }
    if (!is_owned(b.a) && !is_owned(b.b)) continue;
    bonds_.push(b.a, b.b, Real(c.bond_rest_length[k]), static_cast<std::uint8_t>(b.tag));
  }
  // Contact history of the contacts with an owned end waits for the (replayed) rebuild to find
  // their pairs in the lists (check_checkpoint_rows checked models and widths).
  std::vector<ContactRecords*> history;
  for (auto* pc : forces_.history_computes())
    if (pc->pending()) history.push_back(pc->pending());
  for (std::size_t k = 0; k < c.contact_ids.size(); ++k) {
    const auto model = static_cast<std::size_t>(c.contact_model[k]);
    const auto a = c.contact_ids[k][0], b = c.contact_ids[k][1];
    if (is_owned(a) || (b >= 0 && is_owned(b)))  // a wall's id (< 0) has no index
      history[model]->push(a, b, c.contact_history.data() + k * c.contact_width);
  }
  clock_.set(c.step, c.time);
}

template <class Real>
void Simulation<Real>::restore_particle_fields(const io::Checkpoint& c, const std::vector<std::size_t>& mine,
                                               bool replay) {
  // The scene's optional fields that checkpoints store, by name (Particles' array list).
  std::vector<std::string_view> missing;
  p_.for_each_array([&](const ArrayInfo& a, auto& v) {
    if (a.output.empty() || !p_.enabled(a)) return;
    const auto it = std::find_if(c.particle_fields.begin(), c.particle_fields.end(),
                                 [&](const auto& f) { return f.first == a.output; });
    if (it == c.particle_fields.end()) {
      missing.push_back(a.output);
      return;
    }
    using T = std::decay_t<decltype(v[0])>;
    for (std::size_t k = 0; k < mine.size(); ++k) v[k] = static_cast<T>(it->second[mine[k]]);
  });
  if (!p_.with_damage) return;
  const auto& g = c.geometry;
  const auto local_of = [&](std::int64_t id) {
    const auto found = g.index_of(id);
    if (found < 0) return std::int64_t(-1);  // a part of a checkpoint lacks the far ends of its bonds
    const auto gi = static_cast<std::size_t>(found);
    const auto at = std::lower_bound(mine.begin(), mine.end(), gi);
    return at != mine.end() && *at == gi ? static_cast<std::int64_t>(at - mine.begin()) : std::int64_t(-1);
  };
  // A checkpoint without the damage counters (written by a scene without breakable bonds or an older
  // basalt-run): count them from its bonds, broken ones included.
  const bool derive = !missing.empty();
  for (std::size_t k = 0; k < g.bonds.size(); ++k) {
    const auto flag = c.bond_broken[k] & 3;
    for (const auto id : {g.bonds[k].a, g.bonds[k].b}) {
      const auto i = local_of(id);
      if (i < 0) continue;
      const auto li = static_cast<std::size_t>(i);
      if (derive) {
        ++p_.bonds_initial[li];
        p_.bonds_broken[li] += flag == 1 || flag == 2;
      }
      // A bond that broke at the checkpoint's step is restored intact for the replay, whose first force
      // computation breaks (and counts) it again.
      if (flag == 2 && replay) --p_.bonds_broken[li];
    }
  }
}

template <class Real>
void Simulation<Real>::replay_rebuild(const io::Checkpoint& c) {
  // The particles sit at their positions at the last rebuild (distribute_checkpoint), the walls go
  // where that rebuild saw them (step() moves them before rebuilding); the rebuild then reproduces
  // everything the uninterrupted run's did: ownership, order, ghosts, bond order, pair and wall
  // lists, the cell grid, x0 for the skin criterion.
  const auto& g = c.geometry;
  const std::int64_t now = clock_.step();
  clock_.set_step(c.rebuild_step);
  if (!forces_.walls().empty()) forces_.walls().move_to(time_at(c.rebuild_step));
  rebuild();
  clock_.set_step(now);
  restore_servos(c, false);  // from where the rebuild saw them to where the checkpoint has them
  // Back to the checkpoint's positions; the ghosts follow as after any step without a rebuild. A rank
  // holding a part of the checkpoint asks the others for particles a re-balance moved to it during the
  // rebuild (a restart on another rank grid).
  const CheckpointFrame frame(c, origin_);  // positions in the run's frame (mixed precision)
  std::vector<std::int64_t> moved;
  for (std::size_t i = 0; i < p_.n_owned; ++i)
    if (g.index_of(p_.id[i]) < 0) moved.push_back(p_.id[i]);
  std::vector<io::Vec3> moved_at;
  if (comm().size() > 1 && comm().sum(static_cast<long long>(moved.size())) > 0) {
    std::sort(moved.begin(), moved.end());
    std::vector<io::Vec3> held(g.size());
    for (std::size_t i = 0; i < g.size(); ++i) held[i] = frame.position(i, false);
    moved_at = positions_of(comm(), moved, g.id, held);
  }
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    const auto k = g.index_of(p_.id[i]);
    const auto x = k >= 0 ? frame.position(static_cast<std::size_t>(k), false)
                          : moved_at[static_cast<std::size_t>(
                                std::lower_bound(moved.begin(), moved.end(), p_.id[i]) - moved.begin())];
    p_.x[i] = Real(x[0]);
    p_.y[i] = Real(x[1]);
    p_.z[i] = Real(x[2]);
  }
  if (comm().size() > 1) {
    halo_->begin_update_ghosts(p_);
    halo_->end_update_ghosts(p_);
  }
  schedule_.set_pending(c.rebuild_pending);  // a bond broke at the checkpoint step: the next step rebuilds
}

template <class Real>
void Simulation<Real>::restore_servos(const io::Checkpoint& c, bool at_rebuild) {
  // A servo wall's point and velocity are state (no closed form): the checkpoint's, exactly; before
  // replaying the last rebuild, its point at that rebuild (motion_state).
  auto& walls = forces_.walls();
  for (std::size_t w = 0; w < walls.size(); ++w) {
    if (!walls.servo(w)) continue;
    const io::WallState* st = nullptr;
    for (const auto& cw : c.walls)
      if (cw.name == walls.spec(w).name) st = &cw;
    if (!st || (at_rebuild && st->motion_state.size() != 3))
      throw InputError(fmt::format("the checkpoint has no servo state for wall \"{}\" (/walls/{}{})",
                                   walls.spec(w).name, walls.spec(w).name, st ? "/motion_state" : ""));
    const auto x = CheckpointFrame(c, origin_)
                       .point(at_rebuild ? std::array<double, 3>{st->motion_state[0], st->motion_state[1],
                                                                 st->motion_state[2]}
                                         : st->position);
    walls.restore_servo(w, x, st->velocity);
  }
}

#define BASALT_INSTANTIATE(R)                                                                             \
  template Simulation<R>::Simulation(const Scene&, const io::Checkpoint&, const RestartLayout&, MPI_Comm, \
                                     const RunOptions&);                                                  \
  template Simulation<R>::Simulation(const Scene&, const io::CheckpointFile&, const RestartLayout&,       \
                                     MPI_Comm, const RunOptions&);                                        \
  template void Simulation<R>::begin_restart(std::size_t, double, const RestartLayout&);                  \
  template void Simulation<R>::check_checkpoint_rows(const io::Checkpoint&, bool);                        \
  template void Simulation<R>::restore_decomposition(const RestartLayout&, MPI_Comm);                     \
  template void Simulation<R>::distribute_checkpoint(const io::Checkpoint&, const std::vector<double>*,   \
                                                     bool);                                               \
  template void Simulation<R>::finish_restart(const io::Checkpoint&, bool);                               \
  template void Simulation<R>::replay_rebuild(const io::Checkpoint&);                                     \
  template void Simulation<R>::restore_servos(const io::Checkpoint&, bool);                               \
  template void Simulation<R>::restore_particle_fields(const io::Checkpoint&,                             \
                                                       const std::vector<std::size_t>&, bool);
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
