#pragma once
// One DEM run on the compute communicator: particles of this rank's region plus ghosts, bonds,
// contact lists, walls, the stepping loop and the field savers. Physics lives in interactions/,
// communication in parallel/, output behind FieldSink.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/solver/core/bonds.hpp"
#include "basalt/solver/core/id_map.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/interactions/bond_driver.hpp"
#include "basalt/solver/interactions/pair_driver.hpp"
#include "basalt/solver/interactions/wall_driver.hpp"
#include "basalt/solver/neighbor/verlet_list.hpp"
#include "basalt/solver/output/field_sink.hpp"
#include "basalt/solver/parallel/decomposition.hpp"
#include "basalt/solver/parallel/halo.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/timers.hpp"

namespace basalt::solver {

struct RunOptions {
  std::array<int, 3> dims{0, 0, 0};  ///< {0,0,0}: MPI_Dims_create chooses
  bool force_dt = false;             ///< run even above the critical time step
  bool quiet = false;                ///< no progress line
  double progress_seconds = 2.0;     ///< time between progress lines
};

/// The critical time step estimate and what the guard decided.
struct StabilityReport {
  double m_min = 0, k_max = 0, dt_critical = 0, fraction = 0;
  bool warn = false;
};

template <class Real = double>
class Simulation {
 public:
  /// Distributes the geometry over the ranks of `comm` and builds everything the scene needs. The
  /// geometry is taken by value and released part by part as it is copied: pass std::move(g) to keep
  /// peak memory low. Throws InputError (bad scene/geometry combination, unstable dt) on every rank alike.
  Simulation(const Scene& scene, io::Geometry geometry, MPI_Comm comm, const RunOptions& options = {});

  /// Runs `steps` steps (scene.steps when negative), writing field rows to `sink` (rank 0 only; may be null).
  void run(std::int64_t steps = -1, FieldSink* sink = nullptr);
  /// One step.
  void step(FieldSink* sink = nullptr);

  // State and diagnostics (collective where noted).
  std::int64_t current_step() const { return step_; }
  double time() const { return time_; }
  const Particles<Real>& particles() const { return p_; }
  Particles<Real>& particles() { return p_; }
  const Bonds<Real>& bonds() const { return bonds_; }
  const PairList& own_pairs() const { return own_; }
  const PairList& ghost_pairs() const { return ghost_; }
  const Decomposition& decomposition() const { return *dec_; }
  const Comm& comm() const { return dec_->comm(); }
  const PhaseTimes& times() const { return times_; }
  const StabilityReport& stability() const { return stability_; }
  std::int64_t rebuilds() const { return rebuilds_; }
  std::int64_t total_particles() const { return n_global_; }
  double ghost_width() const { return ghost_width_; }
  /// Geometry bonds that no bond group takes (they exert no force).
  std::size_t unassigned_bonds() const { return unassigned_bonds_; }
  const std::vector<BrokenBond>& broken_bonds() const { return broken_; }
  /// Collective: total kinetic energy.
  double kinetic_energy() const;
  /// Collective: {kinetic, bond, contact, wall} energies (recomputes forces' energies; forces unchanged).
  std::array<double, 4> energies();
  /// Collective: number of bonds.
  std::int64_t bond_count() const;
  /// Collective: call after changing particle state from outside (e.g. initial velocities): recomputes
  /// forces and the energy the stability guard starts from.
  void state_changed();
  /// Collective: rebuilds the lists now (migrating particles), then recomputes forces.
  void force_rebuild();
  /// Bytes held by the solver's arrays on this rank (capacity, not RSS).
  std::size_t memory_bytes() const;

 private:
  void distribute(io::Geometry& g, MPI_Comm comm);
  double kinetic_energy_local() const;
  double total_energy(const std::array<double, 3>& pe) const;
  void progress(std::int64_t done, std::int64_t total, double seconds) const;
  void check_stability(const io::Geometry& g);
  void rebuild();
  void resolve_bonds();
  void spatial_sort();
  std::optional<std::string> check_finite() const;
  template <bool Energy>
  std::array<double, 3> compute_forces();
  void save_fields(FieldSink* sink, const std::array<double, 3>& pe);
  void guard_energy(const std::array<double, 3>& pe);
  bool energy_due(std::int64_t s) const;

  Scene scene_;
  RunOptions options_;
  std::unique_ptr<Decomposition> dec_;
  std::unique_ptr<Halo<Real>> halo_;
  Particles<Real> p_;
  Bonds<Real> bonds_;
  IdMap ids_;
  BondDriver<Real, LinearBond> bond_driver_;
  PairDriver<Real, LinearElastic> pair_driver_;
  WallDriver<Real, ElasticWall> wall_driver_;
  PairList own_, ghost_;
  CellGrid grid_;
  Exclusions exclusions_;
  std::vector<BrokenBond> broken_;
  bool bond_broke_ = false;

  Real kick1_ = 0, kick2_ = 0;
  double ghost_width_ = 0;
  double contact_cutoff_ = 0;
  std::size_t unassigned_bonds_ = 0;
  double rebuild_limit2_ = 0;
  std::int64_t n_global_ = 0;
  std::int64_t step_ = 0;
  double time_ = 0;
  std::int64_t rebuilds_ = 0;
  double energy0_ = 0;
  double wall_work_in_ = 0;  ///< this rank's share of the positive work done by walls
  PhaseTimes times_;
  StabilityReport stability_;
};

extern template class Simulation<double>;
extern template class Simulation<float>;

}  // namespace basalt::solver
