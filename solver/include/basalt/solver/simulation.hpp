#pragma once
// One DEM run on the compute communicator: particles of this rank's region plus ghosts, bonds,
// contact lists, walls, the stepping loop and the field savers. Physics lives in interactions/,
// communication in parallel/, output behind FieldSink.
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "basalt/io/checkpoint.hpp"
#include "basalt/io/checkpoint_rows.hpp"
#include "basalt/io/geometry.hpp"
#include "basalt/solver/core/bonds.hpp"
#include "basalt/solver/core/clock.hpp"
#include "basalt/solver/core/fixed_particles.hpp"
#include "basalt/solver/core/id_map.hpp"
#include "basalt/solver/core/ledger.hpp"
#include "basalt/solver/core/particle_flow.hpp"
#include "basalt/solver/core/particle_source.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/integrate/verlet.hpp"
#include "basalt/solver/interactions/force_field.hpp"
#include "basalt/solver/neighbor/rebuild_schedule.hpp"
#include "basalt/solver/neighbor/verlet_list.hpp"
#include "basalt/solver/output/field_observer.hpp"
#include "basalt/solver/output/field_rows.hpp"
#include "basalt/solver/output/field_sink.hpp"
#include "basalt/solver/output/output_sink.hpp"
#include "basalt/solver/parallel/balance.hpp"
#include "basalt/solver/parallel/decomposition.hpp"
#include "basalt/solver/parallel/geometry_loader.hpp"
#include "basalt/solver/parallel/halo.hpp"
#include "basalt/solver/parallel/load_balancer.hpp"
#include "basalt/solver/scene/frame_origin.hpp"
#include "basalt/solver/scene/load_checks.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/stability/energy_guard.hpp"
#include "basalt/solver/stability/rebuild_checks.hpp"
#include "basalt/solver/timers.hpp"

namespace basalt::solver {

struct RunOptions {
  std::array<int, 3> dims{0, 0, 0};  ///< {0,0,0}: MPI_Dims_create chooses
  bool force_dt = false;             ///< run even above the critical time step
  bool force_overlap = false;        ///< start even when particles overlap deeply
  bool quiet = false;                ///< no progress line
  double progress_seconds = 2.0;     ///< time between progress lines
};

/// The critical time step estimate and what the guard decided (solver/src/simulation_stability.cpp,
/// docs/stability.md). dt_critical = 2 / omega_max of the network of bonds, contacts and walls
/// (dt_power), or dt_contact (a contact that forms later) or dt_broken (bonds turned contacts) if smaller.
struct StabilityReport {
  double m_min = 0, k_max = 0, dt_critical = 0, fraction = 0;
  bool warn = false;
  double dt_pair = 0;   ///< the former estimate 2 sqrt(m_min / k_max) (one spring, one particle)
  double dt_bound = 0;  ///< 2 / omega from the bound omega^2 <= max_i (2 sum_j k_ij + sum_walls k) / m_i
  double dt_power = 0;  ///< 2 / omega from power iterations on M^-1 K (the real network)
  /// One new contact of a lightest particle: 2 / sqrt(2 k_pair / m_min) or (wall) k_wall / m_min; with
  /// rotation a tangential spring ks counts as 3.5 ks (the contact point's compliance 1/m + r^2/I = 3.5/m).
  double dt_contact = 0;
  /// Breakable bonds with contacts stiffer than them (a broken bond's pair becomes a contact): the network of
  /// the start with every spring k_pair / k_bond times stiffer, 2 / sqrt(omega_power^2 k_pair / k_bond);
  /// infinite otherwise.
  double dt_broken = std::numeric_limits<double>::infinity();
  int iterations = 0;       ///< power iterations done
  double perturbation = 0;  ///< the largest displacement of the products K u the estimate took
  int retries = 0;          ///< times the perturbation was made 8x smaller because it broke bonds
  double rmin = 0;          ///< smallest radius (the blow-up check's scale)
  double dt_fraction = 0;   ///< run.dt_fraction when the scene chose dt that way
};

/// What a restart needs besides the checkpoint's particles to rebuild the SAME decomposition and
/// lists as the original run (stored in the checkpoint's attributes, docs/formats.md).
struct RestartLayout {
  std::array<double, 3> box_min{0, 0, 0}, box_max{0, 0, 0};  ///< the decomposition's box
  double ghost_width = 0;
  double contact_cutoff = 0;
  /// The cuts in force at the checkpoint (Decomposition::cuts; empty: the even grid). Taken when they
  /// fit the restart's rank grid (as many ranks along each axis), else the grid starts even.
  std::array<std::vector<double>, 3> cuts;
  /// run.precision = "mixed": the origin of the run's frame (scene/frame_origin.hpp); the box and the cuts
  /// above are in that frame (relative to it). Zero in double and float.
  std::array<double, 3> origin{0, 0, 0};
};

/// A caller's job between steps (Python callbacks, stop conditions): run() calls it after every step s with
/// s % every == 0. It returns false to end the run after this step, and must decide alike on every rank (on
/// collective values). With reads_velocities the step before it makes its second half-kick (the velocities
/// are the step's); without, the kick may stay deferred into the next step (velocities half a kick behind,
/// one pass over memory fewer: for hooks that read positions, forces or walls only).
struct StepHook {
  std::int64_t every = 1;
  std::function<bool(std::int64_t step)> call;
  bool reads_velocities = true;
};

template <class Real>
class SimulationFrame;  // output/simulation_frame.hpp: this rank's frame, written for the output

template <class Real = double>
class Simulation {
 public:
  /// Distributes the geometry over the ranks of `comm` and builds everything the scene needs. The
  /// geometry is taken by value and released part by part as it is copied: pass std::move(g) to keep
  /// peak memory low. Throws InputError (bad scene/geometry combination, unstable dt) on every rank alike.
  Simulation(const Scene& scene, io::Geometry geometry, MPI_Comm comm, const RunOptions& options = {});

  /// The same run from a geometry file that no rank reads whole (basalt-run's start-up): each rank reads
  /// a slice of its rows and the ranks route them to their owners (parallel/geometry_loader.hpp). Gives
  /// exactly the state of the constructor above given the whole file; load_stats() tells what was read.
  Simulation(const Scene& scene, const io::GeometryFile& file, MPI_Comm comm, const RunOptions& options = {});

  /// Continues a run from a checkpoint (simulation_restart.cpp): particles, velocities, masses,
  /// bonds with their rest lengths, step and time; the decomposition from `layout`. Replays the
  /// uninterrupted run's last rebuild from the checkpoint's positions at that rebuild, so that on
  /// the same ranks the continued run is bit-for-bit the uninterrupted one (a checkpoint without
  /// them: a plain rebuild, exact to rounding only). Throws InputError when the checkpoint does not fit.
  Simulation(const Scene& scene, const io::Checkpoint& checkpoint, const RestartLayout& layout, MPI_Comm comm,
             const RunOptions& options = {});
  /// The same restart from a checkpoint file that no rank reads whole (basalt-run --restart): each rank
  /// reads a slice of its rows and the ranks route them to their owners (parallel/checkpoint_loader.hpp).
  /// Gives exactly the state of the constructor above given the whole checkpoint.
  Simulation(const Scene& scene, const io::CheckpointFile& file, const RestartLayout& layout, MPI_Comm comm,
             const RunOptions& options = {});

  /// Runs `steps` steps (scene.steps when negative) with output through `out` (simulation_step.cpp): field
  /// partials every saved step, frames (SimulationFrame) when out.frame_kinds() asks, then the hooks due.
  /// An output error stops the run on every rank at the same step (RunError naming it) unless
  /// out.continue_on_error(). Returns the steps made (fewer when a hook ended the run).
  std::int64_t run(std::int64_t steps, OutputSink& out, std::span<const StepHook> hooks = {});
  /// Collective, between runs: writes a checkpoint of the current step through `out` now (none when one of
  /// this step is written already); the output errors so far stop it as in run() (RunError).
  void checkpoint_now(OutputSink& out);
  /// The decomposition's box, ghost width and contact cut-off (stored in checkpoints).
  RestartLayout restart_layout() const;

  /// Runs `steps` steps (scene.steps when negative), writing field rows to `sink` (rank 0 only; may be null).
  void run(std::int64_t steps = -1, FieldSink* sink = nullptr);
  /// One step. On more than one rank a step's field row reaches the sink during the next step (its
  /// reduction overlaps that step's work); run() and flush_fields() deliver the last one.
  void step(FieldSink* sink = nullptr);
  /// Collective: delivers a field row still in flight to the sink.
  void flush_fields(FieldSink* sink);

  // State and diagnostics (collective where noted).
  std::int64_t current_step() const { return clock_.step(); }
  double time() const { return clock_.time(); }
  /// The time step (run.dt, or run.dt_fraction x the critical step).
  double dt() const { return clock_.dt(); }
  const Particles<Real>& particles() const { return p_; }
  /// Mutable access (tests, set-up) drops the kinetic energy cached by the last step.
  Particles<Real>& particles() {
    integrator_.forget_energy();
    return p_;
  }
  const Bonds<Real>& bonds() const { return bonds_; }
  const PairList& own_pairs() const { return forces_.own_pairs(); }
  /// Seconds of force computation by model kind (bond, pair, wall, body), summed since construction.
  const std::array<double, 4>& force_seconds_by_kind() const { return forces_.kind_seconds(); }
  const PairList& ghost_pairs() const { return forces_.ghost_pairs(); }
  const Decomposition& decomposition() const { return *dec_; }
  const Comm& comm() const { return dec_->comm(); }
  const PhaseTimes& times() const { return times_; }
  const StabilityReport& stability() const { return stability_; }
  /// What the time step risks now (dt above the safe fraction of the critical step; rot_bond networks above
  /// stability::kRotBondFraction), one sentence each: basalt-run prints them, the Python package warns.
  std::vector<std::string> step_warnings() const;
  /// The collisions seen at the rebuilds (contact models with a closed form: RebuildChecks::impacts).
  const ImpactReport& impacts() const { return checks_.impact_report(); }
  std::int64_t rebuilds() const { return schedule_.count(); }
  /// Step of the last neighbour-list rebuild.
  std::int64_t last_rebuild_step() const { return schedule_.last_step(); }
  std::int64_t total_particles() const { return n_global_; }
  double ghost_width() const { return ghost_width_; }
  /// The force computes, one per model the scene uses (bond, pair, wall models in that order).
  const std::vector<std::unique_ptr<ForceCompute<Real>>>& force_computes() const {
    return forces_.computes();
  }
  const Walls& walls() const { return forces_.walls(); }
  /// Geometry bonds that no bond group takes (they exert no force).
  std::size_t unassigned_bonds() const { return unassigned_bonds_; }
  const std::vector<BrokenBond>& broken_bonds() const { return broken_; }
  /// Collective: column `column` of fields.csv (field_columns(scene) order) as the savers computed it at this
  /// step, summed over the compute ranks; nullopt when that column's saver was not due at this step.
  std::optional<double> saved_field(std::size_t column) const;
  /// Collective: total kinetic energy.
  double kinetic_energy() const;
  /// Collective: {kinetic, bond, contact, wall} energies (recomputes forces' energies; forces unchanged).
  std::array<double, 4> energies();
  /// The energy ledger's terms, and (collective) their values now (recomputes the potentials).
  const Ledger& ledger() const { return forces_.ledger(); }
  std::vector<double> ledger_values();
  /// Collective: number of bonds.
  std::int64_t bond_count() const;
  /// Collective: call after changing particle state from outside (e.g. initial velocities): recomputes
  /// forces and the energy the stability guard starts from. advance_history: the contacts' history (shear
  /// springs) takes this computation's increment, as a step's does (ESyS's first step increments the spring
  /// of a contact present at the start with the initial velocities: Basalt's ESyS front end).
  void state_changed(bool advance_history = false);
  /// Collective: rebuilds the lists now (migrating particles), then recomputes forces.
  void force_rebuild();

  // Steering between steps (the Python package, docs/python.md): collective, called alike on every rank.
  /// The time step from now on (velocity-dependent models follow it). InputError, nothing changed, unless
  /// positive and finite, or when above the critical step (the start's estimate, or set_contact's) and the
  /// run is not forced (run.force_dt, --force-dt).
  void set_dt(double dt);
  /// Particles of these tags are held from now on (stopped; they feel forces but never move or turn);
  /// replaces the scene's particles.fixed_tags.
  void set_fixed_tags(std::vector<std::int64_t> tags);
  /// The planar wall of that name (InputError naming the scene's walls when none is).
  std::size_t wall_index(std::string_view name) const;
  /// The wall moves at velocity v from now on, from where it is (a servo wall stops steering itself).
  void set_wall_velocity(std::string_view name, const std::array<double, 3>& v);
  /// The wall moves from now on, from where it is, by the motion table `keys` (TOML text of walls[k].motion's
  /// keys, e.g. "type = \"servo\"\ntarget_force = 5.0\ngain = 0.01\nmax_speed = 0.5"; its times count from
  /// now), checked as the scene's. InputError naming the key, nothing changed, on a bad table.
  void set_wall_motion(std::string_view name, const std::string& keys);
  /// Collective: moves the planar wall by u now and recomputes the forces (ESyS-Particle's moveWallBy; the
  /// contacts' history is not advanced again).
  void move_wall_by(std::string_view name, const std::array<double, 3>& u);
  /// The wall touches particles from now on (one the scene declared with active = false, or one removed):
  /// the lists are rebuilt at once and the energy guard takes a new reference. InputError, nothing changed,
  /// when a particle's centre is behind it (the wall would push it through), naming the particle.
  void add_wall(std::string_view name);
  /// The wall stops touching particles (a gate taken away): the lists are rebuilt at once.
  void remove_wall(std::string_view name);
  /// New keys for the [[body_forces]] group `name` (TOML text of its table's keys, e.g. "acceleration = [0.0,
  /// 0.0, -2.0]"), checked as the scene's are; keys not given take their defaults, tags included. Recomputes
  /// the forces and the energy guard's reference (a changed potential is not a change of energy).
  void set_body_force(std::string_view name, const std::string& keys);
  /// New parameters for the contact group `name` (a pair model of [[interactions]]; TOML text of its keys,
  /// e.g. "mu = 0.2"), checked as the scene's are; keys not given take their defaults; its tags stay. The
  /// contacts keep their history. Refused (InputError, nothing changed) when the new parameters reach further
  /// than the lists were built for, or make dt exceed the network's new critical step (unless forced).
  /// Recomputes the forces and the energy guard's reference.
  void set_contact(std::string_view name, const std::string& keys);
  // Particles entering and leaving (simulation_flow.cpp; the scene's [[insert]] and [[delete]] events happen
  // as a step begins): collective, called alike on every rank.
  /// Inserts up to spec.count particles now where they overlap nothing (candidates keyed by spec.seed and
  /// the current step); returns how many went in. InputError when a radius exceeds the run's largest (the
  /// lists' reach) or the particles are too light for dt.
  std::int64_t insert_particles(InsertSpec spec);
  /// Removes the particles of spec's tags (all when empty) whose centre lies in spec.region now, with their
  /// bonds; returns how many.
  std::int64_t remove_particles(DeleteSpec spec);
  /// Removes the particles of every spec at once (one rebuild); returns how many.
  std::int64_t remove_particles(std::vector<DeleteSpec> specs);
  /// Particles inserted and removed since the start of this process's run (restarts count from there).
  const std::array<std::int64_t, 2>& flow_totals() const { return flow_.totals(); }
  /// The id the next inserted particle gets (checkpoints keep it: attribute next_particle_id).
  std::int64_t next_particle_id() const { return flow_.next_id(); }
  /// Every checkpoint from now on carries this root attribute (text), e.g. the stages' progress (stages.hpp).
  void set_checkpoint_attribute(const std::string& key, const std::string& value) {
    checkpoint_attributes_[key] = value;
  }
  /// Whether checkpoints store next_particle_id (a scene with [[insert]], or ids were issued).
  bool keeps_next_id() const { return flow_.ids_issued() || !scene_.inserts.empty(); }
  /// The largest radius the lists reach (the geometry's and the scene's [[insert]]s').
  double largest_radius() const { return flow_.rmax(); }
  /// Collective: the busiest rank's owned particles over the mean (1 = perfectly balanced).
  double imbalance() const { return LoadBalancer<Real>::imbalance(p_, comm(), n_global_); }
  /// run.balance = "pairs"'s estimate of each owned particle's work in a step, a whole number (units of
  /// about 50 instructions): 2 for the particle; per end of a listed pair 1, 4 while the pair touches; per
  /// end of a bond 3; 4 per wall or mesh the particle is a candidate of. A pair or bond with a ghost puts
  /// both ends' share on the owned end (this rank evaluates all of it). From the lists and bonds of the last
  /// rebuild, at the current positions (2 each before the first).
  std::vector<double> pair_work() const { return LoadBalancer<Real>::pair_work(p_, forces_, bonds_); }
  /// run.balance = "time": adds seconds to this rank's measured compute time, as if its steps had taken
  /// them (the balancer then moves work off this rank; tests stand in for a slower core with it).
  void add_rank_work(double seconds) { balancer_.add_rank_work(seconds); }
  /// Times the cuts moved (run.balance = "count" or "time"), and the imbalance (of particles, or of
  /// compute time for "time") before the last move.
  std::int64_t rebalances() const { return balancer_.rebalances(); }
  double imbalance_before_last_rebalance() const { return balancer_.imbalance_before_last_rebalance(); }
  /// Rows this rank read and records it received at start-up (zeros when given a whole geometry).
  const LoadStats& load_stats() const { return load_stats_; }
  /// Bytes held by the solver's arrays on this rank (capacity, not RSS).
  std::size_t memory_bytes() const;
  /// run.precision = "mixed": the origin of the frame the run holds positions, walls and the decomposition
  /// in (positions() + origin() are the absolute coordinates); zero otherwise.
  const Origin& origin() const { return origin_; }
  /// "double", "float" or "mixed" (float storage in a frame at the geometry's centre).
  const char* precision_name() const { return mixed_ ? "mixed" : kPrecision; }

 private:
  /// The precision's name and machine epsilon (load checks, messages).
  static constexpr const char* kPrecision = std::is_same_v<Real, float> ? "float" : "double";
  static constexpr double kEpsilon = double(std::numeric_limits<Real>::epsilon());
  friend class SimulationFrame<Real>;
  /// With BASALT_FRAME_TIMES=1: prints this rank's median/min/max time to pack and submit a frame.
  void report_frame_times(std::vector<double> seconds) const;
  /// The common start of both constructors, before the particles exist (kicks, limits).
  void start(const Scene& scene);
  /// Mixed precision: moves the scene (scene_, the walls) into the frame of origin_ (frame_origin.hpp).
  void enter_frame();
  /// The rank grid over the geometry's box.
  void decompose(const GeometryExtent& e, MPI_Comm comm);
  /// Takes this rank's particles and bonds from `g`: the whole geometry, or this rank's part of it
  /// (GeometryLoader::local_part); the same particles and bonds in the same order either way.
  void distribute(io::Geometry& g, const GeometryExtent& e);
  /// Which optional particle fields the scene needs (both constructors, before any particle exists).
  void configure_particles();
  /// The run's time step: the integrator's kicks and the models' time step (set_time_step).
  void apply_dt(double dt);
  /// The time of `step` (core/clock.hpp: counted from the last set_dt()).
  double time_at(std::int64_t step) const { return clock_.time_at(step); }
  double kinetic_energy_local() const;
  /// Bonds of this rank counted once across ranks (a bond to a ghost by the rank owning the lower id).
  std::int64_t local_bond_count() const;
  /// Collective: the ledger's values summed over ranks, from this rank's potentials pe.
  std::vector<double> ledger_totals(const std::vector<double>& pe) const;
  /// This rank's value of ledger term t (potentials from pe).
  double term_value(std::size_t t, const std::vector<double>& pe) const;
  void progress(std::int64_t done, std::int64_t total, double seconds) const;
  void check_stability(const GeometrySummary& s);
  /// The critical step of one new contact of the lightest particle (mass m_min, radius up to rmax) with
  /// another or with a wall, by the models' stiffness now.
  double contact_critical_step(double m_min, double rmax) const;
  /// Collective, after the first rebuild (simulation_stability.cpp): the network's critical step, dt
  /// from run.dt_fraction (fresh starts), and the refusal above it unless forced.
  void estimate_critical_step(bool fresh);
  /// dt against the critical step: stability_.fraction and .warn, and the refusal above it unless forced
  /// (`what` names the setting in the message).
  void judge_step(const std::string& what);
  /// Collective, before a rebuild: stops the run when a particle moved more than kBlowupRadii rmin in one
  /// step and its path meets another particle or a wall (or it is bonded), or moved to a non-finite
  /// position; a particle in free flight goes on (the rebuild then migrates it however far it went).
  void check_blowup();
  /// Values per particle in blocked_path's list: id, tag, path start (3), path end (3), radius, bonded,
  /// distance or speed (for the message).
  static constexpr std::size_t kFastValues = 11;
  /// Collective: the fast particles' paths (this rank's in `fast`, replaced by every rank's) against every
  /// owned particle's own path (since the last rebuild when `since_rebuild`, else its next step), the
  /// planar walls and the mesh walls. nullopt when all are clear; else, alike on every rank,
  /// "<index in fast>: <what the path meets>".
  std::optional<std::string> blocked_path(std::vector<double>& fast, bool since_rebuild) const;
  /// Collective, after the first rebuild: refuses coincident particles (naming both ids and their
  /// distance) and, at a fresh start unless forced, overlaps deeper than half the smaller radius
  /// between unbonded particles or into a wall; warns (rank 0) of the deepest overlap above 10 %.
  void check_start(bool fresh);
  void rebuild();
  /// Collective, at the end of every rebuild: the collision and rounding checks (RebuildChecks).
  void check_rebuild();
  /// What the balancer reads and moves at this point of the run (LoadBalancer::Run).
  typename LoadBalancer<Real>::Run balance_run() {
    return {
        scene_,      *dec_, *halo_, p_, bonds_, forces_, times_, n_global_, clock_.step(), schedule_.count(),
        ghost_width_};
  }
  /// x0 = the owned positions relative to skin_origin (of the decomposition box), as float: the skin
  /// criterion's reference, set at every rebuild (and restored after the critical-step estimate).
  void set_skin_reference();
  /// Bonds to local indices, in canonical order; returns the bond buckets (Bonds::order_canonically).
  std::vector<std::uint32_t> resolve_bonds();
  void spatial_sort();
  std::optional<std::string> check_finite() const;
  /// Local, before a checkpoint or frame (simulation_stability.cpp): check_finite, and no particle so
  /// fast that its next step moves it farther than check_blowup allows (a finite blown-up state).
  std::optional<std::string> check_frame_state() const;
  /// Forces at the current positions; ghosts_in_flight: a ghost update was begun and is completed
  /// after the owned-only interactions.
  /// advance: a real step (contact history moves on); forces computed outside steps only read it.
  /// Returns this rank's potential energies by ledger term (valid when Energy).
  template <bool Energy>
  const std::vector<double>& compute_forces(bool ghosts_in_flight = false, bool advance = false);
  /// Collective: each servo wall's velocity for the next step from the force on it summed over ranks.
  void steer_servos();
  /// One step (simulation_step.cpp lists its parts in order). With may_defer (run(), when the next thing it
  /// does is another step), velocity Verlet's second half-kick is left for the next step's first pass, which
  /// then makes both (the same bits, one pass over memory fewer) unless something reads the velocities at
  /// this step (a field saver, the energy check).
  void advance(bool may_defer);
  // The parts of a step, in its order; each times itself (times_).
  /// The first half-kick and the drift; returns the largest squared move since the skin reference.
  double drift();
  /// Prescribed and servo walls to the time of `step`.
  void move_walls(std::int64_t step);
  /// Rebuilds the lists when the skin is exceeded, a bond broke or the time balancer asks; otherwise (ranks
  /// > 1) begins the ghosts' update and returns true (it completes inside the force computation).
  bool refresh_neighbours(double moved2);
  /// The step's forces (energies when a saver or the guard reads them); this rank's potentials by term.
  const std::vector<double>& step_forces(bool in_flight);
  /// The second half-kick, deferred when `defer`.
  void second_kick(bool defer);
  /// The walls' work on the particles (energy ledger) and the servo walls' steering.
  void wall_work();
  /// Field savers due and the energy guard.
  void observe(const std::vector<double>& pe);
  /// Whether any hook that reads velocities is due after step s.
  static bool hooks_due(std::span<const StepHook> hooks, std::int64_t s);
  /// Collective: checks the state and hands this rank's share of a frame to `out`.
  void write_frame(OutputSink& out, std::uint32_t kinds, std::vector<double>& seconds);
  /// Collective: a stop signal or an output error on any rank stops every rank here (RunError), unless the
  /// output may fail (on_error = "continue": warned once, `reported`).
  bool agree_on_output(OutputSink& out, bool& reported);
  /// Makes a deferred second half-kick now (run() on its way out, whatever the way).
  void settle_kick();
  /// run()'s guard: settle_kick() when it leaves scope (the last step, an error, a stop signal).
  struct SettleOnExit {
    Simulation& sim;
    ~SettleOnExit() { sim.settle_kick(); }
  };
  /// Whether anything reads the velocities after step s: a field saver or the energy check due.
  bool observed(std::int64_t s) const;
  bool field_partials(const std::vector<double>& pe, std::vector<double>& local,
                      std::vector<char>& due) const;
  /// Collective: the runout saver's value (FieldSpec::percentile of the distances along its direction).
  double runout(const FieldSpec& f) const;
  /// The scene's [[insert]] radii and masses into the stability estimate's (future contacts).
  void include_flow(GeometrySummary& s) const;
  /// At a rebuild, after the ghosts went: the queued flow's particles leave and arrive (ParticleFlow), the
  /// count and the id map follow.
  void exchange_flow();
  /// The queued flow now, between steps: a rebuild, the forces, the ledger's new reference.
  void flow_now();
  /// The energy guard's reference after particles came or went (EnergyGuard::rebase).
  void rebase_ledger(const std::vector<double>& pe);
  /// Restart: what both restart constructors check first (particles, bond groups, dt) and set.
  void begin_restart(std::size_t particles, double dt, const RestartLayout& layout);
  /// Restart: the checkpoint's bonds belong to the scene's bond groups, its contact histories to its
  /// contact models (InputError naming the first row that does not, in file order).
  void check_checkpoint_rows(const io::Checkpoint& rows, bool replay);
  /// Restart: the decomposition, halo, ghost width and contact cut-off of `layout`.
  void restore_decomposition(const RestartLayout& layout, MPI_Comm comm);
  /// Restart: the owned particles of `c` (the whole checkpoint or this rank's part of it), the bonds and
  /// contact histories with an owned end, the clock. `bond_length` (a part's): the distance of each bond's
  /// ends, else computed from c's positions. `replay`: the checkpoint has positions at the last rebuild.
  void distribute_checkpoint(const io::Checkpoint& c, const std::vector<double>* bond_length, bool replay);
  /// Restart: servos, the replayed (or a new) rebuild, the start checks and the energy ledger.
  void finish_restart(const io::Checkpoint& c, bool replay);
  /// Restart: the optional particle fields the checkpoint stores (by name), for the owned particles
  /// (`mine`: their geometry indices in local order); bond damage counters adjusted for the replay.
  void restore_particle_fields(const io::Checkpoint& c, const std::vector<std::size_t>& mine, bool replay);
  /// Restart, after the start's force computation: the last step's forces and torques, which every
  /// checkpoint stores (kick_force_fields), by id, for the first kick; a warning (rank 0) when it has
  /// none (an older checkpoint: then the continuation agrees to rounding only). simulation_kick_forces.cpp.
  void restore_kick_forces(const io::Checkpoint& c);
  /// Restart: the lists of the uninterrupted run's last rebuild (see the restart constructor).
  void replay_rebuild(const io::Checkpoint& c);
  /// Restart: servo walls' point and velocity from the checkpoint (at_rebuild: their point at the last
  /// rebuild, for replay_rebuild()). InputError when the checkpoint lacks them.
  void restore_servos(const io::Checkpoint& c, bool at_rebuild);
  /// Collective: delivers pending output, then throws RunError(message).
  [[noreturn]] void stop(const std::string& message);
  /// Collective: stops the run (naming the fastest particle) when the ledger of this rank's potentials pe
  /// breaks the energy guard's balance.
  void guard_energy(const std::vector<double>& pe);

  Scene scene_;
  RunOptions options_;
  std::unique_ptr<Decomposition> dec_;
  std::unique_ptr<Halo<Real>> halo_;
  Particles<Real> p_;
  Bonds<Real> bonds_;
  IdMap ids_;
  ForceField<Real> forces_;                      ///< the models, their lists and the energy ledger
  EnergyGuard guard_{scene_, forces_.ledger()};  ///< the ledger's reference and balance
  std::vector<BrokenBond> broken_;
  FieldObserver fields_;  ///< the field savers' last row, and the FieldRows of step()/run() given a FieldSink
  FixedParticles fixed_;  ///< owned particles of a fixed tag (from the last rebuild), held

  VelocityVerlet<Real> integrator_;
  double ghost_width_ = 0;
  double contact_cutoff_ = 0;
  std::size_t unassigned_bonds_ = 0;
  std::int64_t n_global_ = 0;
  Clock clock_;  ///< the step, its time, dt and the time of any step
  PhaseTimes times_;
  LoadStats load_stats_;
  double ghost_wait_ = 0;
  StabilityReport stability_;
  OutputSink* output_ = nullptr;  ///< the output of the step being made (run(), step())
  RebuildSchedule schedule_;  ///< when the lists are rebuilt next (skin, a bond broke), and the last rebuild
  RebuildChecks<Real> checks_;   ///< what the rebuilds' collision and rounding checks saw and said
  LoadBalancer<Real> balancer_;  ///< run.balance: its state between rebuilds (parallel/load_balancer.hpp)
  bool mixed_ = false;           ///< run.precision = "mixed" (set by configure_particles())
  Origin origin_{};              ///< the frame's origin (mixed; zero otherwise)
  ParticleFlow<Real> flow_;      ///< particles entering and leaving: the queue, the id counter, the counts
  std::map<std::string, std::string> checkpoint_attributes_;  ///< set_checkpoint_attribute()
  std::int64_t checkpoint_step_ = -1;                         ///< the step of the last checkpoint written
};

/// The last step's force and (with rotation) torque in checkpoints, /particles/<name> float64 (N): what a
/// restart's first kick takes (Simulation::restore_kick_forces).
inline constexpr std::array<std::string_view, 6> kick_force_fields{"force_x",  "force_y",  "force_z",
                                                                   "torque_x", "torque_y", "torque_z"};

extern template class Simulation<double>;
extern template class Simulation<float>;

}  // namespace basalt::solver
