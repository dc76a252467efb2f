#include "basalt/solver/simulation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/integrate/integrators.hpp"
#include "basalt/solver/models/registry.hpp"

namespace basalt::solver {

namespace {

double particle_mass(const io::Geometry& g, std::size_t i, double density) {
  return g.has_mass() ? g.mass[i] : density * 4.0 / 3.0 * std::numbers::pi * std::pow(g.radius[i], 3);
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
Simulation<Real>::Simulation(const Scene& scene, io::Geometry g, MPI_Comm comm, const RunOptions& options)
    : scene_(scene), options_(options), walls_(scene.walls) {
  make_computes();
  p_.with_exact_rebuild = scene.checkpoint_every > 0;
  if (g.size() == 0)
    throw InputError(fmt::format("{}: the geometry has no particles", scene.geometry.string()));
  if (scene.bonds.size() > 254) throw InputError("interactions: at most 254 bond groups");
  const bool se = scene.integrator == Integrator::symplectic_euler;
  kick1_ = Real(se ? scene.dt : scene.dt / 2);
  kick2_ = Real(se ? 0.0 : scene.dt / 2);
  rebuild_limit2_ = 0.25 * scene.skin * scene.skin;
  check_stability(g);
  distribute(g, comm);
  rebuild();
  start_ledger(compute_forces<true>());
}

template <class Real>
void Simulation<Real>::make_computes() {
  computes_ = make_force_computes<Real>(scene_);
  for (auto& c : computes_) {
    if (c->kind() == ModelKind::bond) bond_compute_ = c.get();
    if (c->kind() == ModelKind::pair) pair_computes_.push_back(c.get());
  }
  for (const auto& g : scene_.contacts) {
    std::size_t k = 0;
    while (pair_computes_[k]->model() != g.model) ++k;
    pair_group_compute_.push_back(static_cast<int>(k));
  }
  pairs_take_all_ = scene_.contacts.size() == 1 && scene_.contacts[0].tags.empty();
  // The ledger: every scene has the standard terms (a saver of one nothing fills saves zeros); body
  // forces add theirs.
  for (const auto& name : standard_energy_terms())
    ledger_.add(name, name == "kinetic_energy" ? Ledger::Kind::kinetic
                      : name == "wall_work_in" ? Ledger::Kind::work
                                               : Ledger::Kind::potential);
  kinetic_term_ = static_cast<std::size_t>(ledger_.find("kinetic_energy"));
  wall_work_term_ = static_cast<std::size_t>(ledger_.find("wall_work_in"));
  for (const auto& c : computes_)
    compute_term_.push_back(ledger_.add(c->energy_term(), Ledger::Kind::potential));
  body_term_.assign(ledger_.size(), 0);
  for (std::size_t k = 0; k < computes_.size(); ++k)
    if (computes_[k]->kind() == ModelKind::body) body_term_[compute_term_[k]] = 1;
  pe_.assign(ledger_.size(), 0.0);
  for (std::size_t k = 0; k < scene_.fields.size(); ++k) {
    const auto& f = scene_.fields[k];
    if (f.type == FieldSpec::Type::energy && ledger_.find(f.term) < 0)
      throw InputError(
          fmt::format("output.fields[{}]: type = \"{}\": no model of this scene has that energy term "
                      "(add the body force that owns it)",
                      k, f.term));
  }
  // Checkpoints store all contact histories in one table of one width.
  std::size_t width = 0;
  for (const auto* c : pair_computes_) {
    const auto b = c->history_bytes();
    if (b && width && b != width)
      throw InputError(
          "interactions: contact models with histories of different sizes in one scene are not supported "
          "yet");
    width = std::max(width, b);
  }
}

template <class Real>
int Simulation<Real>::pair_taker(std::int64_t ti, std::int64_t tj) const {
  for (std::size_t g = 0; g < scene_.contacts.size(); ++g) {
    const auto& t = scene_.contacts[g].tags;
    if (t.empty() || (t[0] == ti && t[1] == tj) || (t[0] == tj && t[1] == ti)) return pair_group_compute_[g];
  }
  return -1;
}

template <class Real>
std::vector<ContactRecords*> Simulation<Real>::pending_history() {
  std::vector<ContactRecords*> r;
  for (auto* c : pair_computes_) r.push_back(c->pending());
  return r;
}

template <class Real>
double Simulation<Real>::kinetic_energy_local() const {
  return ke_fresh_ ? ke_local_ : basalt::solver::kinetic_energy(p_);
}

template <class Real>
double Simulation<Real>::term_value(std::size_t t, const std::vector<double>& pe) const {
  if (t == kinetic_term_) return kinetic_energy_local();
  if (t == wall_work_term_) return wall_work_in_;
  return pe[t];
}

template <class Real>
std::vector<double> Simulation<Real>::ledger_totals(const std::vector<double>& pe) const {
  std::vector<double> v(ledger_.size());
  for (std::size_t t = 0; t < v.size(); ++t) v[t] = term_value(t, pe);
  comm().sum_all(v);
  return v;
}

template <class Real>
void Simulation<Real>::start_ledger(const std::vector<double>& pe) {
  ledger0_ = ledger_totals(pe);
  energy0_ = ledger_.mechanical(ledger0_);
}

template <class Real>
std::vector<double> Simulation<Real>::ledger_values() {
  return ledger_totals(compute_forces<true>());
}

template <class Real>
double Simulation<Real>::kinetic_energy() const {
  return comm().sum(kinetic_energy_local());
}

template <class Real>
std::array<double, 4> Simulation<Real>::energies() {
  const auto v = ledger_values();
  const auto term = [&](std::string_view name) { return v[static_cast<std::size_t>(ledger_.find(name))]; };
  return {term("kinetic_energy"), term("bond_potential_energy"), term("contact_potential_energy"),
          term("wall_potential_energy")};
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
void Simulation<Real>::check_stability(const io::Geometry& g) {
  double m_min = std::numeric_limits<double>::infinity(), rmax = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    m_min = std::min(m_min, particle_mass(g, i, scene_.density));
    rmax = std::max(rmax, g.radius[i]);
  }
  double k_max = 0;
  for (const auto& c : computes_) k_max = std::max(k_max, c->max_stiffness(rmax));
  stability_.m_min = m_min;
  stability_.k_max = k_max;
  if (k_max <= 0) return;
  stability_.dt_critical = 2 * std::sqrt(m_min / k_max);
  stability_.fraction = scene_.dt / stability_.dt_critical;
  stability_.warn = stability_.fraction > scene_.dt_safety;
  if (stability_.fraction > 1 && !(scene_.force_dt || options_.force_dt))
    throw InputError(fmt::format(
        "run.dt = {} is {:.3g} times the critical time step {:.6g} (2 sqrt(m_min / k_max), m_min = {:.6g}, "
        "k_max = {:.6g}): the run would be unstable. Lower dt (a safe choice is <= {} x critical), or set "
        "run.force_dt = true / --force-dt to run anyway",
        scene_.dt, stability_.fraction, stability_.dt_critical, m_min, k_max, scene_.dt_safety));
}

template <class Real>
void Simulation<Real>::distribute(io::Geometry& g, MPI_Comm comm) {
  // The decomposition starts from the packing's bounding box; outer ranks own half-infinite regions.
  std::array<double, 3> lo{}, hi{};
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  double rmax = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], g.position[i][d] - g.radius[i]);
      hi[d] = std::max(hi[d], g.position[i][d] + g.radius[i]);
    }
    rmax = std::max(rmax, g.radius[i]);
  }
  dec_ = std::make_unique<Decomposition>(Comm(comm), options_.dims, lo, hi);
  halo_ = std::make_unique<Halo<Real>>(*dec_);
  n_global_ = static_cast<std::int64_t>(g.size());
  ids_.configure(g.id.front(), g.id.back(), g.size());

  // Which bond group takes each geometry bond (first match), and the longest bond.
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
    if (bond_group[k] == kNone) {
      ++unassigned;
      continue;
    }
    longest = std::max(longest, distance(g.position[ia], g.position[ib]));
  }
  unassigned_bonds_ = unassigned;
  ghost_width_ = std::max(pair_computes_.empty() ? 0.0 : 2 * rmax, longest) + scene_.skin;
  contact_cutoff_ = 2 * rmax + scene_.skin;
  if (dec_->min_interior_width() < ghost_width_)
    throw InputError(fmt::format(
        "too many ranks for this geometry: a rank's region would be {:.4g} wide, less than the ghost width "
        "{:.4g} (longest interaction + skin); use fewer ranks or other --dims (now {}x{}x{})",
        dec_->min_interior_width(), ghost_width_, dec_->dims()[0], dec_->dims()[1], dec_->dims()[2]));

  std::vector<char> owned(g.size(), 0);
  std::size_t n_mine = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const auto& x = g.position[i];
    owned[i] = dec_->owns(x[0], x[1], x[2]);
    n_mine += static_cast<std::size_t>(owned[i]);
  }
  // Bonds with an owned end, then particles; each part of the geometry is released once copied, so
  // the geometry and the solver's copy never coexist in full (peak memory).
  std::size_t n_bonds = 0;
  for (std::size_t k = 0; k < g.bonds.size(); ++k)
    if (bond_group[k] != kNone)
      n_bonds += owned[static_cast<std::size_t>(g.index_of(g.bonds[k].a))] ||
                 owned[static_cast<std::size_t>(g.index_of(g.bonds[k].b))];
  bonds_.grouped = scene_.bonds.size() > 1;
  bonds_.reserve(n_bonds);
  for (std::size_t k = 0; k < g.bonds.size(); ++k) {
    if (bond_group[k] == kNone) continue;
    const auto& b = g.bonds[k];
    const auto ia = static_cast<std::size_t>(g.index_of(b.a)), ib = static_cast<std::size_t>(g.index_of(b.b));
    if (!owned[ia] && !owned[ib]) continue;
    const double r0 = bond_compute_->rest_length(bond_group[k], g.radius[ia], g.radius[ib],
                                                 distance(g.position[ia], g.position[ib]));
    bonds_.push(b.a, b.b, Real(r0), bond_group[k]);
  }
  std::vector<io::Bond>().swap(g.bonds);
  std::vector<std::uint8_t>().swap(bond_group);
  p_.reserve_owned(n_mine);
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (!owned[i]) continue;
    const auto& x = g.position[i];
    p_.push_owned(g.id[i], Real(x[0]), Real(x[1]), Real(x[2]), Real(g.radius[i]), g.tag[i],
                  Real(1.0 / particle_mass(g, i, scene_.density)));
  }
  std::vector<io::Vec3>().swap(g.position);
  std::vector<double>().swap(g.radius);
  std::vector<double>().swap(g.mass);
  std::vector<std::int32_t>().swap(g.tag);
}

template <class Real>
std::optional<std::string> Simulation<Real>::check_finite() const {
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    const bool ok = std::isfinite(p_.x[i]) && std::isfinite(p_.y[i]) && std::isfinite(p_.z[i]) &&
                    std::isfinite(p_.vx[i]) && std::isfinite(p_.vy[i]) && std::isfinite(p_.vz[i]) &&
                    std::isfinite(p_.fx[i]) && std::isfinite(p_.fy[i]) && std::isfinite(p_.fz[i]);
    if (!ok)
      return fmt::format(
          "step {}: particle id {} went non-finite: position ({}, {}, {}), velocity ({}, {}, {}), force ({}, "
          "{}, "
          "{}); dt = {} is {:.3g} x the critical time step",
          step_, p_.id[i], p_.x[i], p_.y[i], p_.z[i], p_.vx[i], p_.vy[i], p_.vz[i], p_.fx[i], p_.fy[i],
          p_.fz[i], scene_.dt, stability_.fraction);
  }
  return std::nullopt;
}

template <class Real>
void Simulation<Real>::spatial_sort() {
  // Owned particles in cell order: neighbours in space become neighbours in memory. Within a cell
  // by id, so the order is a function of the owned (id, position) set alone, never of the order
  // migration or a restart left them in: every rebuild is canonical (a restart replays one bit for
  // bit, docs/ARCHITECTURE.md). A cell holds a few particles: sorting them costs little.
  grid_.build(p_.x, p_.y, p_.z, p_.n_owned, contact_cutoff_);
  const auto& order = grid_.order();
  const auto& start = grid_.start();
  std::vector<std::uint32_t> perm(order.begin(), order.end());
  const auto by_id = [&](std::uint32_t i, std::uint32_t j) { return p_.id[i] < p_.id[j]; };
  for (std::size_t c = 0; c + 1 < start.size(); ++c)
    if (start[c + 1] - start[c] > 1) std::sort(perm.begin() + start[c], perm.begin() + start[c + 1], by_id);
  p_.permute_owned(perm);
}

template <class Real>
void Simulation<Real>::resolve_bonds() {
  ids_.assign(p_.id, p_.size());
  std::optional<std::string> error;
  const std::size_t nb = bonds_.size(), n = p_.n_owned;
  bonds_.ia.resize(nb);
  bonds_.ib.resize(nb);
  for (std::size_t k = 0; k < nb; ++k) {
    auto ia = ids_.find(bonds_.a[k]), ib = ids_.find(bonds_.b[k]);
    if ((ia < 0 || ib < 0) && !error) {
      error = fmt::format(
          "step {}: the bond between particle ids {} and {} is longer than the ghost width {:.6g} (particle "
          "{} "
          "is not within reach of rank {}): bonds must not stretch beyond the longest initial bond + skin",
          step_, bonds_.a[k], bonds_.b[k], ghost_width_, ia < 0 ? bonds_.a[k] : bonds_.b[k], comm().rank());
      if (stability_.warn)
        *error += fmt::format(" (dt is {:.3g} x the critical time step: the run is probably unstable)",
                              stability_.fraction);
      ia = std::max(ia, 0);
      ib = std::max(ib, 0);
    }
    // Owned end first; both owned: the lower index first (a canonical orientation, whatever
    // orientation the bond arrived in).
    if (static_cast<std::size_t>(ia) >= n || (static_cast<std::size_t>(ib) < n && ib < ia)) {
      std::swap(ia, ib);
      std::swap(bonds_.a[k], bonds_.b[k]);
    }
    bonds_.ia[k] = ia;
    bonds_.ib[k] = ib;
  }
  if (comm().size() > 1) error = comm().agree_error(error);
  if (error) stop(*error);
  // Both ends owned first, each part in memory order of its owned end (a counting sort: O(bonds)),
  // then by the other end within a bucket: a total order on (ghost?, ia, ib), so the bond order
  // (and with it the force summation order) is canonical like the particles'.
  std::vector<std::uint32_t> start(2 * n + 1, 0);
  auto key = [&](std::size_t k) {
    return (static_cast<std::size_t>(bonds_.ib[k]) >= n ? n : 0) + static_cast<std::size_t>(bonds_.ia[k]);
  };
  for (std::size_t k = 0; k < nb; ++k) ++start[key(k) + 1];
  for (std::size_t c = 0; c < 2 * n; ++c) start[c + 1] += start[c];
  std::vector<std::uint32_t> order(nb);
  for (std::size_t k = 0; k < nb; ++k) order[start[key(k)]++] = static_cast<std::uint32_t>(k);
  for (std::size_t c = 0, b = 0; c < 2 * n; b = start[c], ++c)
    if (start[c] - b > 1)
      std::sort(order.begin() + static_cast<std::ptrdiff_t>(b), order.begin() + start[c],
                [&](std::uint32_t i, std::uint32_t j) { return bonds_.ib[i] < bonds_.ib[j]; });
  bonds_.permute(order);
  // start[c] is now the end of bucket c: the bonds of owned particle i are the bucket i (both ends
  // owned) and n + i (to a ghost). The pair-list build uses these buckets to exclude bonded pairs.
  bond_bucket_end_.swap(start);
  bonds_.n_both_owned = 0;
  while (bonds_.n_both_owned < nb && static_cast<std::size_t>(bonds_.ib[bonds_.n_both_owned]) < n)
    ++bonds_.n_both_owned;
}

template <class Real>
void Simulation<Real>::rebuild() {
  Stopwatch sw;
  auto error = check_finite();
  const bool parallel = comm().size() > 1;
  if (parallel) error = comm().agree_error(error);
  if (error) stop(*error);
  for (auto* c : pair_computes_) c->save_history(p_);  // before the ghosts (and the pairs' ids) go
  p_.drop_ghosts();
  if (parallel) {
    error = halo_->migrate(p_, bonds_, pending_history());
    error = comm().agree_error(error);
    if (error) stop(*error);
    const long long total = comm().sum(static_cast<long long>(p_.n_owned));
    if (total != n_global_)
      stop(fmt::format("step {}: {} particles on the ranks, {} expected: particles were lost", step_, total,
                       n_global_));
  }
  times_.communication += sw.lap();
  spatial_sort();
  times_.neighbor += sw.lap();
  if (parallel) halo_->build_ghosts(p_, ghost_width_);
  times_.communication += sw.lap();
  resolve_bonds();
  if (!pair_computes_.empty()) {
    // Cells half the longest cutoff: each particle searches only as far as it can reach (a third or a
    // quarter measured slower on the 30 mm cube: more rows to step through).
    grid_.size_to(p_.x, p_.y, p_.z, p_.size(), contact_cutoff_ / 2);
    grid_.fill(p_.x, p_.y, p_.z, 0, p_.n_owned);
    ghost_grid_.size_like(grid_);
    ghost_grid_.fill(p_.x, p_.y, p_.z, p_.n_owned, p_.size());
    exclusions_.bind(bond_bucket_end_, bonds_.ib, p_.n_owned);
    if (pairs_take_all_) {
      build_pair_lists(
          p_, grid_, ghost_grid_, scene_.skin, exclusions_, [](std::size_t, std::size_t) { return true; },
          own_, ghost_);
    } else {
      auto accept = [this](std::size_t i, std::size_t j) { return pair_taker(p_.tag[i], p_.tag[j]) >= 0; };
      build_pair_lists(p_, grid_, ghost_grid_, scene_.skin, exclusions_, accept, own_, ghost_);
    }
    std::vector<std::uint32_t>().swap(bond_bucket_end_);
    const PairLists<Real> lists{
        p_, own_, ghost_, pair_computes_.size(),
        [this](std::size_t i, std::size_t j) { return pair_taker(p_.tag[i], p_.tag[j]); }};
    for (std::size_t k = 0; k < pair_computes_.size(); ++k) pair_computes_[k]->rebuild(lists, k);
  }
  grid_.release();
  ghost_grid_.release();
  if (!walls_.empty()) walls_.rebuild(p_, scene_.skin);
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    p_.x0[i] = float(p_.x[i]);
    p_.y0[i] = float(p_.y[i]);
    p_.z0[i] = float(p_.z[i]);
  }
  if (p_.with_exact_rebuild) {  // exact copies for the checkpoints (x0 is float); memory only then
    p_.xr.assign(p_.x.begin(), p_.x.begin() + static_cast<std::ptrdiff_t>(p_.n_owned));
    p_.yr.assign(p_.y.begin(), p_.y.begin() + static_cast<std::ptrdiff_t>(p_.n_owned));
    p_.zr.assign(p_.z.begin(), p_.z.begin() + static_cast<std::ptrdiff_t>(p_.n_owned));
  }
  rebuild_step_ = step_;
  bond_broke_ = false;
  ++rebuilds_;
  if (std::getenv("BASALT_DEBUG_REBUILD"))
    fmt::print(stderr, "rank {} rebuild at step {} owned {} ghosts {} bonds {} (both owned {}) pairs {}+{}\n",
               comm().rank(), step_, p_.n_owned, p_.n_ghost(), bonds_.size(), bonds_.n_both_owned,
               own_.pairs(), ghost_.pairs());
  times_.neighbor += sw.lap();
}

template <class Real>
template <bool Energy>
const std::vector<double>& Simulation<Real>::compute_forces(bool ghosts_in_flight, bool advance) {
  // Interactions among owned particles first: a ghost update still in flight overlaps them.
  if (!forces_zeroed_) zero_forces(p_);
  forces_zeroed_ = false;
  if (Energy) std::fill(pe_.begin(), pe_.end(), 0.0);
  const std::size_t before = broken_.size();
  if (!walls_.empty()) walls_.move_to(time_);
  ForceState<Real> state{p_, bonds_, broken_, walls_};
  // Bond models come first in the list: by the time the pair models start, the neighbours' ghost
  // posts have arrived and one poke moves them along.
  bool poked = !ghosts_in_flight;
  for (std::size_t k = 0; k < computes_.size(); ++k) {
    if (!poked && computes_[k]->kind() != ModelKind::bond) {
      halo_->progress_ghosts();
      poked = true;
    }
    pe_[compute_term_[k]] += computes_[k]->compute(state, Part::owned, Energy, advance);
  }
  if (ghosts_in_flight) {
    Stopwatch sw;
    halo_->end_update_ghosts(p_);
    ghost_wait_ += sw.lap();
  }
  for (std::size_t k = 0; k < computes_.size(); ++k)
    pe_[compute_term_[k]] += computes_[k]->compute(state, Part::ghost, Energy, advance);
  if (broken_.size() != before) bond_broke_ = true;  // the lists must learn the pair is now unbonded
  for (std::size_t k = before; k < broken_.size(); ++k) broken_[k].step = step_;
  return pe_;
}

template <class Real>
bool Simulation<Real>::energy_due(std::int64_t s) const {
  for (const auto& f : scene_.fields)
    if (s % f.every == 0 &&
        (f.type == FieldSpec::Type::total_energy ||
         (f.type == FieldSpec::Type::energy &&
          ledger_[static_cast<std::size_t>(ledger_.find(f.term))].kind == Ledger::Kind::potential)))
      return true;
  return scene_.energy_check_every > 0 && s % scene_.energy_check_every == 0;
}

template <class Real>
bool Simulation<Real>::kinetic_due(std::int64_t s) const {
  for (const auto& f : scene_.fields)
    if (s % f.every == 0 && (f.type == FieldSpec::Type::total_energy ||
                             (f.type == FieldSpec::Type::energy && f.term == "kinetic_energy")))
      return true;
  return scene_.energy_check_every > 0 && s % scene_.energy_check_every == 0;
}

template <class Real>
void Simulation<Real>::step(FieldSink* sink) {
  ke_fresh_ = false;
  sink_ = sink;
  Stopwatch sw;
  // Forces are zeroed in the same pass: the non-finite check needs them only at a rebuild, and a
  // non-finite force has already made the velocity non-finite.
  const double moved2 = kick_zero_drift(p_, kick1_, Real(scene_.dt));
  forces_zeroed_ = true;
  times_.integration += sw.lap();
  const bool parallel = comm().size() > 1;
  if (!walls_.empty()) walls_.move_to(double(step_ + 1) * scene_.dt);
  double need = bond_broke_ ? std::numeric_limits<double>::infinity()
                            : std::max(moved2, walls_.empty() ? 0.0 : walls_.moved2_since_rebuild());
  if (parallel) need = comm().max(need);
  times_.communication += sw.lap();
  bool in_flight = false;
  if (!(need <= rebuild_limit2_)) {
    rebuild();
    rebuild_step_ = step_ + 1;  // the positions it used are those of the step being completed
    sw.lap();
  } else if (parallel) {
    halo_->begin_update_ghosts(p_);
    in_flight = true;
    times_.communication += sw.lap();
  }
  ++step_;
  time_ = double(step_) * scene_.dt;
  const bool energy = energy_due(step_);
  ghost_wait_ = 0;
  const auto pe = energy ? compute_forces<true>(in_flight, true) : compute_forces<false>(in_flight, true);
  const double force_time = sw.lap();
  times_.forces += force_time - ghost_wait_;
  times_.communication += ghost_wait_;
  if (kick2_ != Real(0)) {
    if (kinetic_due(step_)) {
      ke_local_ = kick_energy(p_, kick2_);
      ke_fresh_ = true;
    } else {
      kick(p_, kick2_);
    }
  }
  times_.integration += sw.lap();
  if (!walls_.empty()) wall_work_in_ += std::max(0.0, walls_.power(time_)) * scene_.dt;
  save_fields(sink, pe);
  times_.output += sw.lap();
  if (scene_.energy_check_every > 0 && step_ % scene_.energy_check_every == 0) guard_energy(pe);
}

template <class Real>
void Simulation<Real>::save_fields(FieldSink* sink, const std::vector<double>& pe) {
  if (output_) return output_fields(pe);
  std::vector<double> local;
  std::vector<char> due;
  const bool any = field_partials(pe, local, due);
  if (!any) return;
  if (comm().size() == 1) {
    if (!sink) return;
    std::vector<std::optional<double>> row(local.size());
    for (std::size_t c = 0; c < local.size(); ++c)
      if (due[c]) row[c] = local[c];
    sink->row(step_, time_, row);
    return;
  }
  finish_row(sink);
  if (!row_sum_) row_sum_ = std::make_unique<AsyncSum>(comm());
  row_sum_->start(std::move(local));
  row_step_ = step_;
  row_time_ = time_;
  row_due_ = std::move(due);
}

template <class Real>
void Simulation<Real>::stop(const std::string& message) {
  // Collective (every caller has agreed on the error): deliver the row in flight, then stop.
  finish_row(sink_);
  if (sink_ && comm().rank() == 0) sink_->flush();
  throw RunError(message);
}

template <class Real>
void Simulation<Real>::finish_row(FieldSink* sink) {
  if (!row_sum_ || !row_sum_->active()) return;
  const auto& sums = row_sum_->finish();
  if (comm().rank() != 0 || !sink) return;
  std::vector<std::optional<double>> row(sums.size());
  for (std::size_t c = 0; c < sums.size(); ++c)
    if (row_due_[c]) row[c] = sums[c];
  sink->row(row_step_, row_time_, row);
}

template <class Real>
void Simulation<Real>::guard_energy(const std::vector<double>& pe) {
  // The ledger's balance: mechanical energy + dissipated - work put in stays at the start's
  // mechanical energy E0. Allowed growth: |E0| + the work put in + what was dissipated + how far each
  // body force's potential moved (energy it released): an error of 100 % of every source at once.
  // Without body forces or dissipation this is E > 2 (E0 + W).
  const auto v = ledger_totals(pe);
  const double e = ledger_.mechanical(v), w = ledger_.sum(v, Ledger::Kind::work),
               d = ledger_.sum(v, Ledger::Kind::dissipated);
  double released = 0;
  for (std::size_t t = 0; t < v.size(); ++t)
    if (body_term_[t]) released += std::abs(v[t] - ledger0_[t]);
  const double imbalance = e + d - w - energy0_, allowed = std::abs(energy0_) + w + d + released;
  if (imbalance <= allowed && std::isfinite(e)) return;
  // Name the fastest particle.
  double best = -1;
  std::size_t bi = 0;
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    const double ke =
        0.5 * double(p_.mass(i)) * double(p_.vx[i] * p_.vx[i] + p_.vy[i] * p_.vy[i] + p_.vz[i] * p_.vz[i]);
    if (!(ke <= best)) {
      best = ke;
      bi = i;
    }
  }
  const auto [top, who] = comm().max_loc(std::isfinite(best) ? best : std::numeric_limits<double>::max());
  std::string msg;
  if (comm().rank() == who && p_.n_owned > 0) {
    std::string terms;
    for (std::size_t t = 0; t < v.size(); ++t)
      terms += fmt::format("{}{} {:.6g}", t ? ", " : "", ledger_[t].name, v[t]);
    msg = fmt::format(
        "step {}: the energy grows without a source: mechanical energy {:.6g} + dissipated {:.6g} - work put "
        "in "
        "{:.6g} exceeds the initial {:.6g} by {:.6g}, more than allowed ({:.6g}); ledger: {}. Fastest "
        "particle: "
        "id {} with kinetic energy {:.6g}, velocity ({:.6g}, {:.6g}, {:.6g}) at ({:.6g}, {:.6g}, {:.6g}). dt "
        "= {} "
        "is {:.3g} x the critical time step {:.6g}",
        step_, e, d, w, energy0_, imbalance, allowed, terms, p_.id[bi], best, p_.vx[bi], p_.vy[bi], p_.vz[bi],
        p_.x[bi], p_.y[bi], p_.z[bi], scene_.dt, stability_.fraction, stability_.dt_critical);
  }
  stop(comm().broadcast(msg, who));
}

template <class Real>
void Simulation<Real>::progress(std::int64_t done, std::int64_t total, double seconds) const {
  const double sps = done / std::max(seconds, 1e-9);
  fmt::print("step {:>8}/{}  {:8.1f} steps/s  {:6.2f} M particle-steps/s  ETA {:.1f} s\n", step_,
             step_ + (total - done), sps, sps * double(n_global_) * 1e-6,
             (total - done) / std::max(sps, 1e-9));
  std::fflush(stdout);
}

template <class Real>
void Simulation<Real>::run(std::int64_t steps, FieldSink* sink) {
  if (steps < 0) steps = scene_.steps;
  Stopwatch clock;
  double elapsed = 0, last = 0;
  const bool show = !options_.quiet && comm().rank() == 0;
  for (std::int64_t k = 0; k < steps; ++k) {
    step(sink);
    if (show && (k & 15) == 15) {
      elapsed += clock.lap();
      if (elapsed - last >= options_.progress_seconds) {
        progress(k + 1, steps, elapsed);
        last = elapsed;
      }
    }
  }
  finish_row(sink);
  if (sink && comm().rank() == 0) sink->flush();
}

template <class Real>
void Simulation<Real>::state_changed() {
  ke_fresh_ = false;
  wall_work_in_ = 0;
  start_ledger(compute_forces<true>());
}

template <class Real>
void Simulation<Real>::force_rebuild() {
  ke_fresh_ = false;
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
  b += own_.memory_bytes() + ghost_.memory_bytes() + ids_.memory_bytes() + halo_->memory_bytes() +
       walls_.memory_bytes();
  for (const auto& c : computes_) b += c->memory_bytes();
  return b;
}

template class Simulation<double>;
template class Simulation<float>;

}  // namespace basalt::solver
