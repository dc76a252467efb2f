#pragma once
// A run as the scene file (TOML, docs/scenes.md) describes it. parse_scene() checks every key:
// an unknown or misspelled key, a wrong type, a missing file or an impossible value is an InputError
// naming the file, line and key.
#include <any>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/flow_spec.hpp"
#include "basalt/solver/scene/stage_spec.hpp"
#include "basalt/solver/scene/wall_motion.hpp"

namespace basalt::solver {

/// Particle-tag filter of an interaction group: empty = every particle; for pairs {a, b} = pairs
/// with one end tagged a and the other b (either order).
using TagFilter = std::vector<std::int64_t>;

/// One [[interactions]] group: a registered model (models/registry.hpp), its parameters as the model
/// parsed them, and what it applies to.
struct InteractionSpec {
  std::string name;
  std::string model;  ///< the registry name (type = "...")
  ModelKind kind = ModelKind::pair;
  std::any params;  ///< Model::Params
  TagFilter tags;
  std::optional<std::int64_t> bond_tag;  ///< bonds only: the geometry's bond tag this group takes

  template <class Model>
  const typename Model::Params& params_of() const {
    return std::any_cast<const typename Model::Params&>(params);
  }
};

struct WallSpec {
  std::string name;
  std::array<double, 3> point{0, 0, 0};
  std::array<double, 3> normal{0, 0, 1};  ///< unit length after parsing
  std::string model = "elastic";          ///< the registry name of its wall model (interaction = "...")
  std::any params;                        ///< Model::Params
  TagFilter tags;                         ///< particle tags the wall touches (empty: all)
  /// interaction = "bonded": tags of the particles tied to the wall (candidates wherever they are).
  TagFilter bond_tags;
  WallMotion motion;
  /// Touches no particle: active = false in the scene (added later), or taken away (a stage's remove_walls,
  /// replayed by a restart: stages.hpp).
  bool removed = false;

  bool bonds(std::int64_t tag) const {
    for (const auto t : bond_tags)
      if (t == tag) return true;
    return false;
  }
  template <class Model>
  const typename Model::Params& params_of() const {
    return std::any_cast<const typename Model::Params&>(params);
  }
};

/// One [[mesh_walls]] entry: a triangle mesh (STL/OBJ/OFF, placed by scale and offset when parsed) acting
/// through a wall model, moved rigidly: a translation (WallMotion) and a rotation at a constant angular
/// velocity about an axis through a point (the point travels with the translation). docs/scenes.md.
struct MeshWallSpec {
  std::string name;
  std::filesystem::path file;                   ///< resolved against the scene's folder
  std::vector<std::array<double, 3>> vertices;  ///< after scale and offset (the rest pose)
  std::vector<std::array<std::int32_t, 3>> triangles;
  bool one_sided = false;                     ///< sides = "one": only the normals' side touches
  std::string model = "elastic";              ///< the registry name of its wall model
  std::any params;                            ///< Model::Params
  TagFilter tags;                             ///< particle tags the wall touches (empty: all)
  WallMotion motion;                          ///< translation
  std::array<double, 3> axis{0, 0, 1};        ///< rotation axis (unit)
  std::array<double, 3> axis_point{0, 0, 0};  ///< a point on the axis at t = 0
  double angular_velocity = 0;                ///< radians per time unit, right-handed about axis

  bool moves() const { return motion.moves() || angular_velocity != 0; }
  template <class Model>
  const typename Model::Params& params_of() const {
    return std::any_cast<const typename Model::Params&>(params);
  }
};

/// One field saver ([[output.fields]]): a term of the energy ledger (kinetic_energy, the potentials,
/// wall_work_in, a body force's potential), the total mechanical energy, the bond count, or a wall's
/// force (planar or mesh wall), the mass of the particles below a height (mass_below: discharge), or
/// the mean vertical velocity of the particles above a height (mean_vz_above: a wave's arrival).
struct FieldSpec {
  enum class Type {
    energy,
    total_energy,
    bond_count,
    wall_force,
    wall_position,
    rotational_kinetic_energy,
    sliding_contacts,
    runout,
    mass_below,
    mean_vz_above,
    broken_bonds  ///< four columns: bonds broken so far in tension, shear, bending, torsion
  };
  Type type = Type::energy;
  std::string term = "kinetic_energy";  ///< energy only: the ledger term
  std::int64_t every = 1;
  std::string wall;  ///< wall_force and wall_position only
  /// wall_force and wall_position: three columns <name>_<wall>_x, _y, _z.
  bool per_wall() const { return type == Type::wall_force || type == Type::wall_position; }
  /// runout: the distance along `direction` from `origin` that `percentile` % of the particles do not
  /// pass (100: the farthest particle).
  std::array<double, 3> origin{0, 0, 0}, direction{1, 0, 0};
  double percentile = 100;
  double z = 0;  ///< mass_below, mean_vz_above: particles whose centre is below / above this height
  /// Columns it writes: wall_force and wall_position 3 (x, y, z), broken_bonds 4 (per failure mode), the
  /// others 1.
  std::size_t width() const { return per_wall() ? 3 : (type == Type::broken_bonds ? 4 : 1); }
  /// Appended to the name when an earlier saver has the same name with other parameters (another
  /// direction or origin of a runout, another z): "_fields<k>", k its index in output.fields.
  std::string suffix;
  /// The column name (wall_force, wall_position, broken_bonds: the prefix of their columns).
  std::string name() const { return base_name() + suffix; }
  /// Whether `o` saves the same values (its `every` aside).
  bool same_values(const FieldSpec& o) const {
    return type == o.type && term == o.term && wall == o.wall && origin == o.origin &&
           direction == o.direction && percentile == o.percentile && z == o.z;
  }
  /// The name by type and parameters: a runout's percentile is in it, written whole ("runout_p99") or
  /// with '_' for the decimal point ("runout_p99_5"): every percentile has its own name.
  std::string base_name() const {
    switch (type) {
      case Type::energy:
        return term;
      case Type::total_energy:
        return "total_energy";
      case Type::bond_count:
        return "bond_count";
      case Type::wall_force:
        return "wall_force";
      case Type::wall_position:
        return "wall_position";
      case Type::rotational_kinetic_energy:
        return "rotational_kinetic_energy";
      case Type::sliding_contacts:
        return "sliding_contacts";
      case Type::mass_below:
        return "mass_below";
      case Type::mean_vz_above:
        return "mean_vz_above";
      case Type::broken_bonds:
        return "broken_bonds";
      case Type::runout: {
        if (percentile >= 100) return "runout_max";
        if (percentile == std::floor(percentile))
          return "runout_p" + std::to_string(static_cast<long long>(percentile));
        // Up to 6 significant digits; a decimal point in a column name would be dropped by some CSV readers.
        std::string p = std::to_string(percentile);  // e.g. "99.500000"
        while (!p.empty() && p.back() == '0') p.pop_back();
        for (auto& c : p)
          if (c == '.') c = '_';
        return "runout_p" + p;
      }
    }
    return term;
  }
};

/// Ledger terms every scene has (a saver of one the scene's models do not fill saves zeros).
inline const std::vector<std::string>& standard_energy_terms() {
  static const std::vector<std::string> t{"kinetic_energy", "bond_potential_energy",
                                          "contact_potential_energy", "wall_potential_energy",
                                          "wall_work_in"};
  return t;
}

enum class Integrator { velocity_verlet, symplectic_euler };

struct Scene {
  std::filesystem::path file;  ///< the scene file ("" when parsed from text)
  std::string text;            ///< its content (provenance)
  struct {
    std::string length = "mm", time = "ms", force = "N";
  } units;
  std::filesystem::path geometry;  ///< resolved against the scene file's folder
  double density = 1;
  /// [particles] rotation: particles rotate (angular velocity and torque; ESyS "RotSphere").
  bool rotation = false;
  /// [particles] orientation: rotating particles keep their orientation (a unit quaternion, in frames and
  /// checkpoints); on when a model reads orientations (rot_bond), else off unless the scene asks for it.
  bool orientation = false;
  /// [particles] fixed_tags: particles of these tags feel forces but never move or turn (ESyS
  /// setParticleNonDynamic): rough bases, anchors.
  std::vector<std::int64_t> fixed_tags;
  double dt = 0;           ///< run.dt; with run.dt_fraction 0 until the simulation sets it
  double dt_fraction = 0;  ///< run.dt_fraction: dt = this x the critical step (0: run.dt is given)
  /// run.precision: "double" or "float" (basalt-run's Simulation<Real>), or "mixed" (Simulation<float> in a
  /// frame at the geometry's centre with a compensated drift: scene/frame_origin.hpp)
  std::string precision = "double";
  std::int64_t steps = 0;
  double skin = 0;
  Integrator integrator = Integrator::velocity_verlet;
  bool force_dt = false;
  bool force_overlap = false;             ///< start even when particles overlap deeply (each other or a wall)
  double dt_safety = 0.2;                 ///< warn when dt > dt_safety * critical step
  std::int64_t energy_check_every = 100;  ///< 0: no energy-growth guard
  /// run.balance: "none" (the even grid, never moved), "count" (cuts moved at a rebuild so that each
  /// slab of the rank grid holds an equal share of the particles: parallel/balance.hpp), "pairs" (the
  /// same, each particle weighted by its listed pairs, bonds and walls: Simulation::pair_work) or "time"
  /// (every run.balance_every steps, cuts moved so that each slab takes an equal share of the measured
  /// compute time: a particle weighs its rank's compute time over its particle count).
  std::string balance = "none";
  /// run.balance_threshold: re-balance when the busiest rank holds more than this x the mean particles
  /// ("count"), this x the mean work ("pairs") or took more than this x the mean compute time ("time");
  /// 0: the mode's default.
  double balance_threshold = 0;
  /// run.balance_every: with "time", the steps between two checks of the ranks' compute times.
  std::int64_t balance_every = 500;
  /// The threshold in force: balance_threshold, or 1.2 for "count", 1.02 for "pairs" and 1.05 for "time"
  /// when it is 0.
  double balance_limit() const {
    if (balance_threshold > 0) return balance_threshold;
    return balance == "time" ? 1.05 : balance == "pairs" ? 1.02 : 1.2;
  }
  std::vector<InteractionSpec> bonds;     ///< bond groups, in scene order (a bond's group indexes these)
  std::vector<InteractionSpec> contacts;  ///< pair (contact) groups, in scene order
  std::vector<WallSpec> walls;
  std::vector<MeshWallSpec> mesh_walls;  ///< their history ids follow the planar walls' (-1 - (walls + k))
  std::vector<InteractionSpec> body_forces;  ///< [[body_forces]]: tags = the particle tags it acts on
  std::filesystem::path output_dir = "out";
  std::vector<FieldSpec> fields;
  std::vector<StageSpec> stages;  ///< [[stages]]: run in order instead of run.steps (stages.hpp)
  /// The clock's base: time = time + (step - step) x dt from this step on, with dt the step in force then (0:
  /// run.dt). Zero, unless a restart of a staged run replays a stage's dt change (stages.hpp, replay_stages);
  /// run.dt stays the run's first step (the checkpoints' dt).
  struct {
    double time = 0;
    std::int64_t step = 0;
    double dt = 0;
  } clock_base;
  std::vector<InsertSpec> inserts;  ///< [[insert]]: particles poured in (scene/flow_spec.hpp)
  std::vector<DeleteSpec> deletes;  ///< [[delete]]: particles taken out (outlets)
  // [output] frames and checkpoints (written by the I/O layer; docs/io-ranks.md)
  std::int64_t checkpoint_every = 0;      ///< HDF5 checkpoint every N steps (0 = off)
  std::int64_t frames_every = 0;          ///< VTK frame every N steps (0 = off)
  bool output_continue_on_error = false;  ///< on_error = "continue": a failed output does not stop the run
  std::int64_t render_every = 0;          ///< in-situ picture every N steps (I/O ranks; 0 = off)
  std::string render;  ///< the pictures' spec, "color=velocity_z,cut=y" (io::parse_render_spec)
  std::int64_t frames_in_flight = 2;  ///< per compute rank: frames posted but not yet received
};

/// A scene's largest size in bytes (10 MB): its text is stored in every checkpoint.
inline constexpr std::uintmax_t kMaxSceneBytes = 10'000'000;

/// Reads and checks a scene file. Throws InputError naming file, line and key.
Scene parse_scene(const std::filesystem::path& file);
/// Same from text; `label` names the source in errors, relative paths resolve against `base_dir`.
Scene parse_scene_text(const std::string& text, const std::string& label,
                       const std::filesystem::path& base_dir);

/// A planar wall's motion table (walls[k].motion; Simulation::set_wall_motion), `normal` the wall's.
WallMotion parse_motion(TableReader& t, const std::array<double, 3>& normal);

/// Column names of fields.csv for these savers (after "step" and "time").
std::vector<std::string> field_columns(const Scene& scene);
/// The columns one saver writes (wall_force x, y, z; broken_bonds one per failure mode; else one).
std::vector<std::string> field_columns(const FieldSpec& f);

}  // namespace basalt::solver
