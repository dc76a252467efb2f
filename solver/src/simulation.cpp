#include "basalt/solver/simulation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/core/sphere_mass.hpp"
#include "basalt/solver/integrate/integrators.hpp"
#include "basalt/solver/models/registry.hpp"
#include "basalt/solver/scene/load_checks.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

namespace {

double particle_mass(const io::Geometry& g, std::size_t i, double density) {
  return g.has_mass() ? g.mass[i] : sphere_mass(density, g.radius[i]);
}

double distance(const io::Vec3& a, const io::Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

bool tags_match(const TagFilter& t, std::int64_t ta, std::int64_t tb) {
  return t.empty() || (t[0] == ta && t[1] == tb) || (t[0] == tb && t[1] == ta);
}

}  // namespace

template <class Real>
void Simulation<Real>::start(const Scene& scene) {
  configure_particles();
  if (scene.bonds.size() > 254) throw InputError("interactions: at most 254 bond groups");
  apply_dt(scene_.dt);
  clock_.set_base(scene_.clock_base.step, scene_.clock_base.time);
  schedule_.configure(scene.skin);
}

template <class Real>
Simulation<Real>::Simulation(const Scene& scene, io::Geometry g, MPI_Comm comm, const RunOptions& options)
    : scene_(scene), options_(options), forces_(scene) {
  if (g.size() == 0)
    throw InputError(fmt::format("{}: the geometry has no particles", scene.geometry.string()));
  start(scene);
  if (mixed_) {  // everything in the frame at the geometry's centre from here on
    origin_ = frame_origin(extent_of(g));
    geometry_to_frame(g, origin_);
    enter_frame();
  }
  const auto summary = summarize_geometry(scene_, g, scene.geometry.string());
  run_load_checks(scene_, summary, scene.geometry.string(), comm, kEpsilon, precision_name());
  GeometryExtent extent = extent_of(g);
  flow_.include(scene_, extent);
  check_stability(summary);
  decompose(extent, comm);
  distribute(g, extent);
  rebuild();
  check_start(true);
  estimate_critical_step(true);  // simulation_stability.cpp; may set dt (run.dt_fraction)
  guard_.start(forces_.ledger(), ledger_totals(compute_forces<true>()));
}

template <class Real>
Simulation<Real>::Simulation(const Scene& scene, const io::GeometryFile& file, MPI_Comm comm,
                             const RunOptions& options)
    : scene_(scene), options_(options), forces_(scene) {
  if (file.header().particles == 0)
    throw InputError(fmt::format("{}: the geometry has no particles", scene.geometry.string()));
  start(scene);
  const Comm all(comm);
  GeometryLoader loader(file, all);
  if (mixed_) {  // everything in the frame at the geometry's centre from here on
    origin_ = frame_origin(loader.extent());
    loader.to_frame(origin_);
    enter_frame();
  }
  // The checks see the whole geometry through the slices' summaries (mins, maxima and tag sets are exact).
  const auto summary =
      merge_summaries(summarize_geometry(scene_, loader.slice(), scene.geometry.string()), comm);
  run_load_checks(scene_, summary, scene.geometry.string(), comm, kEpsilon, precision_name());
  GeometryExtent extent = loader.extent();
  flow_.include(scene_, extent);
  check_stability(summary);
  decompose(extent, comm);
  io::Geometry part = loader.local_part(*dec_);
  load_stats_ = loader.stats();
  distribute(part, extent);
  rebuild();
  check_start(true);
  estimate_critical_step(true);
  guard_.start(forces_.ledger(), ledger_totals(compute_forces<true>()));
}

template <class Real>
void Simulation<Real>::enter_frame() {
  scene_to_frame(scene_, origin_);
  forces_.walls() = Walls(scene_.walls, scene_.mesh_walls);
}

template <class Real>
void Simulation<Real>::configure_particles() {
  // The optional field groups this scene needs (Particles::enabled()): nothing else is allocated.
  mixed_ = scene_.precision == "mixed";
  // Compensated drift in mixed precision (BASALT_MIXED_COMPENSATION=0 leaves it out: the measurement of
  // what it buys, tools/studies/mixed_precision.py).
  const char* comp = std::getenv("BASALT_MIXED_COMPENSATION");
  p_.with_compensation = mixed_ && !(comp && std::string(comp) == "0");
  p_.with_exact_rebuild = scene_.checkpoint_every > 0;
  p_.with_damage = forces_.bonds_can_break();
  p_.with_rotation = scene_.rotation;
  p_.with_orientation = scene_.rotation && (scene_.orientation || forces_.needs_bond_frame());
  p_.with_bond_frame = forces_.needs_bond_frame();
  p_.ghost_velocity = forces_.needs_ghost_velocity();
}

template <class Real>
double Simulation<Real>::kinetic_energy_local() const {
  return integrator_.kinetic_energy().value_or(basalt::solver::kinetic_energy(p_)) + rotational_energy(p_);
}

template <class Real>
double Simulation<Real>::kinetic_energy() const {
  return comm().sum(kinetic_energy_local());
}

template <class Real>
std::int64_t Simulation<Real>::local_bond_count() const {
  auto c = static_cast<std::int64_t>(bonds_.n_both_owned);
  for (std::size_t k = bonds_.n_both_owned; k < bonds_.size(); ++k)
    c += p_.id[static_cast<std::size_t>(bonds_.ia[k])] < p_.id[static_cast<std::size_t>(bonds_.ib[k])];
  return c;
}

template <class Real>
std::int64_t Simulation<Real>::bond_count() const {
  return comm().sum(static_cast<long long>(local_bond_count()));
}

template <class Real>
void Simulation<Real>::decompose(const GeometryExtent& e, MPI_Comm comm) {
  // The decomposition starts from the packing's bounding box; outer ranks own half-infinite regions.
  dec_ = std::make_unique<Decomposition>(Comm(comm), options_.dims, e.lo, e.hi);
  halo_ = std::make_unique<Halo<Real>>(*dec_);
}

template <class Real>
void Simulation<Real>::distribute(io::Geometry& g, const GeometryExtent& e) {
  const double rmax = e.rmax;
  n_global_ = e.n;
  ids_.configure(e.first_id, e.last_id, static_cast<std::size_t>(e.n));
  std::vector<char> owned(g.size(), 0);
  std::size_t n_mine = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const auto& x = g.position[i];
    owned[i] = dec_->owns(x[0], x[1], x[2]);
    n_mine += static_cast<std::size_t>(owned[i]);
  }

  // Which bond group takes each geometry bond (first match), and the longest bond. Each bond is counted
  // by the rank owning its first end (once across ranks, whether g is the whole geometry or a part).
  constexpr std::uint8_t kNone = 255;
  std::vector<std::uint8_t> bond_group(g.bonds.size(), kNone);
  double longest = 0;
  std::size_t unassigned = 0;
  for (std::size_t k = 0; k < g.bonds.size(); ++k) {
    const auto& b = g.bonds[k];
    const auto ia = static_cast<std::size_t>(g.index_of(b.a)), ib = static_cast<std::size_t>(g.index_of(b.b));
    for (std::size_t gi = 0; gi < scene_.bonds.size(); ++gi) {
      const auto& grp = scene_.bonds[gi];
      if (grp.bond_tag && *grp.bond_tag != b.tag) continue;
      if (!tags_match(grp.tags, g.tag[ia], g.tag[ib])) continue;
      bond_group[k] = static_cast<std::uint8_t>(gi);
      break;
    }
    if (!owned[ia]) continue;
    if (bond_group[k] == kNone) {
      ++unassigned;
      continue;
    }
    longest = std::max(longest, distance(g.position[ia], g.position[ib]));
  }
  longest = comm().max(longest);
  unassigned_bonds_ = static_cast<std::size_t>(comm().sum(static_cast<long long>(unassigned)));
  // (a cohesive pair model reaches beyond touching: forces_.pair_reach, 0 for contact by overlap)
  const double reach = forces_.pair_reach(rmax);
  ghost_width_ = std::max(forces_.has_pairs() ? 2 * rmax + reach : 0.0, longest) + scene_.skin;
  contact_cutoff_ = 2 * rmax + reach + scene_.skin;
  if (dec_->min_interior_width() < ghost_width_)
    throw InputError(fmt::format(
        "too many ranks for this geometry: a rank's region would be {:.4g} wide, less than the ghost width "
        "{:.4g} (longest interaction + skin); use fewer ranks or other --dims (now {}x{}x{})",
        dec_->min_interior_width(), ghost_width_, dec_->dims()[0], dec_->dims()[1], dec_->dims()[2]));

  // Bonds with an owned end, then particles; each part of the geometry is released once copied, so
  // the geometry and the solver's copy never coexist in full (peak memory).
  std::size_t n_bonds = 0;
  for (std::size_t k = 0; k < g.bonds.size(); ++k)
    if (bond_group[k] != kNone)
      n_bonds += owned[static_cast<std::size_t>(g.index_of(g.bonds[k].a))] ||
                 owned[static_cast<std::size_t>(g.index_of(g.bonds[k].b))];
  bonds_.grouped = scene_.bonds.size() > 1;
  bonds_.reserve(n_bonds);
  std::vector<std::int32_t> initial;  // bonds of each particle (with breakable bonds: damage)
  if (p_.with_damage) initial.assign(g.size(), 0);
  for (std::size_t k = 0; k < g.bonds.size(); ++k) {
    if (bond_group[k] == kNone) continue;
    const auto& b = g.bonds[k];
    const auto ia = static_cast<std::size_t>(g.index_of(b.a)), ib = static_cast<std::size_t>(g.index_of(b.b));
    if (!owned[ia] && !owned[ib]) continue;
    const double r0 = forces_.rest_length(bond_group[k], g.radius[ia], g.radius[ib],
                                          distance(g.position[ia], g.position[ib]));
    bonds_.push(b.a, b.b, Real(r0), bond_group[k]);
    if (p_.with_damage) {
      ++initial[ia];
      ++initial[ib];
    }
  }
  std::vector<io::Bond>().swap(g.bonds);
  std::vector<std::uint8_t>().swap(bond_group);
  p_.reserve_owned(n_mine);
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (!owned[i]) continue;
    const auto& x = g.position[i];
    p_.push_owned(g.id[i], Real(x[0]), Real(x[1]), Real(x[2]), Real(g.radius[i]), g.tag[i],
                  Real(1.0 / particle_mass(g, i, scene_.density)));
    if (p_.with_damage) p_.bonds_initial.back() = initial[i];
  }
  std::vector<io::Vec3>().swap(g.position);
  std::vector<double>().swap(g.radius);
  std::vector<double>().swap(g.mass);
  std::vector<std::int32_t>().swap(g.tag);
}

template <class Real>
template <bool Energy>
const std::vector<double>& Simulation<Real>::compute_forces(bool ghosts_in_flight, bool advance) {
  // Interactions among owned particles first: a ghost update still in flight overlaps them.
  if (!integrator_.take_zeroed()) zero_forces(p_);
  if (Energy) forces_.zero_energies();
  const std::size_t before = broken_.size();
  if (!forces_.walls().empty()) forces_.walls().move_to(clock_.time());
  ForceState<Real> state{p_, bonds_, broken_, forces_.walls()};
  // Bond models come first: by the time the others start, the neighbours' ghost posts have arrived
  // and one poke moves them along.
  forces_.add(state, Part::owned, Energy, advance, [&] {
    if (ghosts_in_flight) halo_->progress_ghosts();
  });
  if (ghosts_in_flight) {
    Stopwatch sw;
    halo_->end_update_ghosts(p_);
    ghost_wait_ += sw.lap();
  }
  forces_.add(state, Part::ghost, Energy, advance, [] {});
  fixed_.hold(p_);
  if (!bonds_.parted.empty()) {
    // The lists must learn that the pairs are unbonded: at once where they list bonded pairs, else by
    // a rebuild before the next force computation.
    if (forces_.lists_mark_bonds())
      forces_.unbond(bonds_.parted);
    else
      schedule_.bond_parted();
    bonds_.parted.clear();
  }
  for (std::size_t k = before; k < broken_.size(); ++k) broken_[k].step = clock_.step();
  return forces_.potentials();
}

template <class Real>
void Simulation<Real>::steer_servos() {
  // The force on a servo wall is every rank's share summed (the same sum on every rank, so each moves
  // it alike); its control law (WallMotion::servo) is free of MPI.
  auto& walls = forces_.walls();
  if (!walls.has_servo()) return;
  std::vector<double> f;
  for (std::size_t w = 0; w < walls.size(); ++w)
    if (walls.servo(w)) f.insert(f.end(), walls.force(w).begin(), walls.force(w).end());
  if (comm().size() > 1) comm().sum_all(f);
  std::size_t k = 0;
  for (std::size_t w = 0; w < walls.size(); ++w)
    if (walls.servo(w)) {
      walls.steer_servo(w, {f[k], f[k + 1], f[k + 2]});
      k += 3;
    }
}

template <class Real>
void Simulation<Real>::apply_dt(double dt) {
  scene_.dt = dt;
  clock_.set_dt(dt);
  integrator_.configure(dt, scene_.integrator == Integrator::symplectic_euler);
  for (const auto& c : forces_.computes()) c->set_time_step(dt);  // velocity-dependent models' increments
}

template <class Real>
void Simulation<Real>::set_dt(double dt) {
  if (!(dt > 0) || !std::isfinite(dt))
    throw InputError(fmt::format("dt = {}: must be positive and finite", dt));
  if (stability_.dt_critical > 0) {  // refused, nothing changed, as the scene's dt is at the start
    const double before = scene_.dt;
    const StabilityReport stability = stability_;
    scene_.dt = dt;
    try {
      judge_step(fmt::format("dt (set at step {})", clock_.step()));
      stability_.warn = stability_.fraction > scene_.dt_safety;  // (not run.dt_fraction's choice any more)
    } catch (const InputError&) {
      scene_.dt = before;
      stability_ = stability;
      throw;
    }
  }
  // The clock goes on from now at the new step (a step x dt clock would jump, and the walls' motions with
  // it).
  clock_.rebase();
  apply_dt(dt);
}

template <class Real>
void Simulation<Real>::set_fixed_tags(std::vector<std::int64_t> tags) {
  scene_.fixed_tags = std::move(tags);
  fixed_.find(p_, scene_.fixed_tags);
  // Held from now on: at rest, and the forces of this step (the next kick's) zeroed as after every force
  // computation.
  fixed_.stop(p_);
  fixed_.hold(p_);
}

template <class Real>
std::size_t Simulation<Real>::wall_index(std::string_view name) const {
  const auto& walls = forces_.walls();
  for (std::size_t w = 0; w < walls.size(); ++w)
    if (walls.spec(w).name == name) return w;
  std::string names;
  for (std::size_t w = 0; w < walls.size(); ++w) names += (w ? ", " : "") + walls.spec(w).name;
  throw InputError(fmt::format("no planar wall named \"{}\" (the scene's walls: {})", name,
                               names.empty() ? "none" : names));
}

template <class Real>
void Simulation<Real>::set_wall_velocity(std::string_view name, const std::array<double, 3>& v) {
  for (double c : v)
    if (!std::isfinite(c)) throw InputError(fmt::format("wall \"{}\": the velocity must be finite", name));
  forces_.walls().set_velocity(wall_index(name), v, clock_.time());
}

namespace {

/// The TOML text of a group's keys given from a script (set_body_force, set_contact); InputError naming the
/// group when it does not parse.
toml::table parse_group_keys(const std::string& keys, const std::string& label) {
  try {
    return toml::parse(keys, label);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}: {}", label, e.description()));
  }
}

}  // namespace

template <class Real>
void Simulation<Real>::set_wall_motion(std::string_view name, const std::string& keys) {
  const std::size_t w = wall_index(name);
  auto& walls = forces_.walls();
  const std::string label = fmt::format("walls \"{}\".motion", name);
  const toml::table table = parse_group_keys(keys, label);
  TableReader t(table, label, std::string(name) + ".motion");
  const WallMotion m = parse_motion(t, walls.spec(w).normal);
  t.finish();
  walls.set_motion(w, m, clock_.time());
}

template <class Real>
void Simulation<Real>::move_wall_by(std::string_view name, const std::array<double, 3>& u) {
  for (double c : u)
    if (!std::isfinite(c))
      throw InputError(fmt::format("wall \"{}\": the displacement must be finite", name));
  forces_.walls().shift(wall_index(name), u);
  state_changed();
}

template <class Real>
void Simulation<Real>::add_wall(std::string_view name) {
  const std::size_t w = wall_index(name);
  auto& walls = forces_.walls();
  if (!walls.removed(w)) return;
  // A particle it touches whose centre is behind the plane would be pushed through it: refused (collective).
  std::int64_t behind = 0, first = -1;
  for (std::size_t i = 0; i < p_.n_owned; ++i)
    if (walls.touches_tag(w, p_.tag[i]) && walls.distance(w, p_.x[i], p_.y[i], p_.z[i]) < 0 && behind++ == 0)
      first = p_.id[i];
  if (comm().size() > 1) {
    behind = comm().sum(static_cast<long long>(behind));
    first = static_cast<std::int64_t>(comm().max(static_cast<double>(first)));
  }
  if (behind > 0)
    throw InputError(
        fmt::format("wall \"{}\" cannot be added: {} particle(s) have their centre behind it (e.g. "
                    "id {}), and it would push them through; move it first (its motion) or "
                    "delete them",
                    name, behind, first));
  walls.restore(w);
  rebuild();
  state_changed();  // (the forces with the wall, and the energy guard's new reference)
}

template <class Real>
void Simulation<Real>::remove_wall(std::string_view name) {
  forces_.walls().remove(wall_index(name));
  force_rebuild();
}

template <class Real>
void Simulation<Real>::set_body_force(std::string_view name, const std::string& keys) {
  auto it = std::find_if(scene_.body_forces.begin(), scene_.body_forces.end(),
                         [&](const InteractionSpec& b) { return b.name == name; });
  if (it == scene_.body_forces.end()) {
    std::string names;
    for (const auto& b : scene_.body_forces) names += (names.empty() ? "" : ", ") + b.name;
    throw InputError(
        fmt::format("no body force named \"{}\" (the scene's: {})", name, names.empty() ? "none" : names));
  }
  InteractionSpec spec = *it;
  const std::string label = fmt::format("body_forces \"{}\"", name);
  const toml::table table = parse_group_keys(keys, label);
  TableReader t(table, label, std::string(name));
  spec.params = find_model(spec.model, ModelKind::body)->parse(t);
  spec.tags = t.integers_or("tags", {});
  t.finish();
  for (const auto& c : forces_.computes())
    if (c->reconfigure(spec)) {
      *it = spec;
      state_changed();
      return;
    }
  throw InputError(fmt::format("{}: no force compute took it (a bug)", label));
}

template <class Real>
void Simulation<Real>::set_contact(std::string_view name, const std::string& keys) {
  auto it = std::find_if(scene_.contacts.begin(), scene_.contacts.end(),
                         [&](const InteractionSpec& g) { return g.name == name; });
  if (it == scene_.contacts.end()) {
    const bool bond = std::any_of(scene_.bonds.begin(), scene_.bonds.end(),
                                  [&](const InteractionSpec& g) { return g.name == name; });
    std::string names;
    for (const auto& g : scene_.contacts) names += (names.empty() ? "" : ", ") + g.name;
    throw InputError(
        fmt::format("no contact group named \"{}\"{} (the scene's contact groups: {})", name,
                    bond ? ": it is a bond group, and bonds keep the parameters they were made with" : "",
                    names.empty() ? "none" : names));
  }
  const std::string label = fmt::format("interactions \"{}\"", name);
  const toml::table table = parse_group_keys(keys, label);
  TableReader t(table, label, std::string(name));
  InteractionSpec spec = *it;
  spec.params = find_model(spec.model, ModelKind::pair)->parse(t);
  t.finish();  // (no tags key: which pairs a group takes is fixed at the start)
  const InteractionSpec before = *it;
  const StabilityReport stability = stability_;
  const auto take = [&](const InteractionSpec& g) {
    for (const auto& c : forces_.computes())
      if (c->reconfigure(g)) return;
    throw InputError(fmt::format("{}: no force compute took it (a bug)", label));
  };
  take(spec);
  // The lists were built for the reach the scene's models had at the start (contact_cutoff_).
  const double reach = forces_.pair_reach(flow_.rmax());
  if (2 * flow_.rmax() + reach + scene_.skin > contact_cutoff_ * (1 + 1e-12)) {
    take(before);
    throw InputError(
        fmt::format("{}: the new parameters reach {:.6g} beyond touching, further than the lists were built "
                    "for ({:.6g}): "
                    "give the scene the far-reaching parameters from the start and weaken them here instead",
                    label, reach, contact_cutoff_ - 2 * flow_.rmax() - scene_.skin));
  }
  // A stiffer contact shortens the critical step: the network's estimate again, refused as at the start.
  try {
    stability_.dt_contact = contact_critical_step(stability_.m_min, flow_.rmax());
    stability_.k_max = forces_.max_stiffness(flow_.rmax());
    estimate_critical_step(false);
  } catch (const InputError& e) {
    take(before);
    stability_ = stability;
    compute_forces<false>();  // (the estimate used the force arrays as scratch)
    throw InputError(fmt::format("{}: {}", label, e.what()));
  }
  *it = spec;
  state_changed();
}

template <class Real>
void Simulation<Real>::state_changed(bool advance_history) {
  integrator_.forget_energy();
  guard_.clear_wall_work();
  guard_.start(forces_.ledger(), ledger_totals(compute_forces<true>(false, advance_history)));
}

template <class Real>
void Simulation<Real>::force_rebuild() {
  integrator_.forget_energy();
  rebuild();
  compute_forces<false>();
}

template <class Real>
std::size_t Simulation<Real>::memory_bytes() const {
  std::size_t b = 0;
  auto add = [&](const auto& v) {
    b += v.capacity() * sizeof(typename std::decay_t<decltype(v)>::value_type);
  };
  b += p_.memory_bytes();
  add(bonds_.a);
  add(bonds_.b);
  add(bonds_.r0);
  add(bonds_.group);
  add(bonds_.ia);
  add(bonds_.ib);
  b += forces_.memory_bytes() + ids_.memory_bytes() + halo_->memory_bytes();
  return b;
}

template class Simulation<double>;
template class Simulation<float>;
// The step (simulation_step.cpp) and the stability estimate call both; explicit, as they are member
// templates.
template const std::vector<double>& Simulation<double>::compute_forces<true>(bool, bool);
template const std::vector<double>& Simulation<double>::compute_forces<false>(bool, bool);
template const std::vector<double>& Simulation<float>::compute_forces<true>(bool, bool);
template const std::vector<double>& Simulation<float>::compute_forces<false>(bool, bool);

}  // namespace basalt::solver
