// The model registry: one line per model in model_registry(). A model header (models/*.hpp) plus its
// line here is all a new model takes (docs/ARCHITECTURE.md, "How to add a model").
#include "basalt/solver/models/registry.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <set>
#include <type_traits>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/interactions/body_driver.hpp"
#include "basalt/solver/interactions/bond_driver.hpp"
#include "basalt/solver/interactions/bonded_wall_driver.hpp"
#include "basalt/solver/interactions/mesh_wall_driver.hpp"
#include "basalt/solver/interactions/pair_driver.hpp"
#include "basalt/solver/interactions/rot_bond_driver.hpp"
#include "basalt/solver/interactions/wall_driver.hpp"
#include "basalt/solver/models/bonded_wall.hpp"
#include "basalt/solver/models/contact_age.hpp"
#include "basalt/solver/models/contract.hpp"
#include "basalt/solver/models/damping.hpp"
#include "basalt/solver/models/elastic_wall.hpp"
#include "basalt/solver/models/friction.hpp"
#include "basalt/solver/models/gravity.hpp"
#include "basalt/solver/models/hertz_mindlin.hpp"
#include "basalt/solver/models/jkr.hpp"
#include "basalt/solver/models/linear_bond.hpp"
#include "basalt/solver/models/linear_elastic.hpp"
#include "basalt/solver/models/rolling_friction.hpp"
#include "basalt/solver/models/rot_bond.hpp"

namespace basalt::solver {

namespace {

template <class Real, class Model>
std::unique_ptr<ForceCompute<Real>> make(const Scene& s) {
  if constexpr (Model::kind == ModelKind::bond) {
    if constexpr (requires { Model::rotational; })
      return std::make_unique<RotBondDriver<Real, Model>>(s.bonds);
    else
      return std::make_unique<BondDriver<Real, Model>>(s.bonds);
  }
  if constexpr (Model::kind == ModelKind::pair) return std::make_unique<PairDriver<Real, Model>>(s.contacts);
  if constexpr (Model::kind == ModelKind::wall) {
    if constexpr (requires { Model::bonded; })
      return std::make_unique<BondedWallDriver<Real, Model>>(s.walls);
    else
      return std::make_unique<WallDriver<Real, Model>>(s.walls);
  }
  if constexpr (Model::kind == ModelKind::body)
    return std::make_unique<BodyDriver<Real, Model>>(s.body_forces);
}

template <class Real, class Model>
std::unique_ptr<ForceCompute<Real>> make_mesh(const Scene& s) {
  return std::make_unique<MeshWallDriver<Real, Model>>(s.mesh_walls, s.walls.size());
}

template <class Real, class Model>
constexpr auto mesh_maker() -> std::unique_ptr<ForceCompute<Real>> (*)(const Scene&) {
  if constexpr (Model::kind == ModelKind::wall && !requires { Model::bonded; })
    return &make_mesh<Real, Model>;
  else
    return nullptr;
}

template <class Model>
constexpr std::string_view energy_term_of() {
  if constexpr (requires { Model::energy_term; })
    return Model::energy_term;
  else
    return {};
}

template <class Model>
constexpr std::string_view dissipation_term_of() {
  if constexpr (requires { Model::dissipation_term; })
    return Model::dissipation_term;
  else
    return {};
}

template <class Model>
constexpr auto float_problem_of() -> std::string_view (*)(const std::any&) {
  if constexpr (requires { Model::float_problem; })
    return [](const std::any& p) {
      return Model::float_problem(std::any_cast<const typename Model::Params&>(p));
    };
  else
    return nullptr;
}

template <class Model>
ModelEntry entry() {
  static_assert(check_model<Model>());
  return {Model::name,
          Model::kind,
          Model::summary,
          Model::keys,
          Model::reads,
          Model::writes,
          history_bytes<Model>(),
          energy_term_of<Model>(),
          dissipation_term_of<Model>(),
          [](TableReader& t) { return std::any(Model::parse(t)); },
          [](const std::any& p, double rmax) {
            return Model::max_stiffness(std::any_cast<const typename Model::Params&>(p), rmax);
          },
          &make<double, Model>,
          &make<float, Model>,
          mesh_maker<double, Model>(),
          mesh_maker<float, Model>(),
          float_problem_of<Model>()};
}

}  // namespace

const std::vector<ModelEntry>& model_registry() {
  static const std::vector<ModelEntry> models{
      entry<LinearBond>(),         // bond
      entry<RotBond>(),            // bond, ESyS RotBond/BrittleBeam (Wang et al. 2006)
      entry<LinearElastic>(),      // pair
      entry<ContactAge>(),         // pair, test model for contact history
      entry<Friction>(),           // pair, ESyS NRotFriction
      entry<RotFriction>(),        // pair, ESyS RotFriction
      entry<RollingFriction>(),    // pair, rot_friction with rolling resistance (Ai et al. 2011)
      entry<HertzMindlin>(),       // pair, LIGGGHTS hertz/history, ESyS HertzMindlinVisco
      entry<Jkr>(),                // pair, JKR adhesion (cohesive powders)
      entry<ElasticWall>(),        // wall
      entry<FrictionWall>(),       // wall, with Coulomb friction
      entry<HertzMindlinWall>(),   // wall
      entry<BondedWall>(),         // wall, ESyS NRotBondedWall
      entry<Gravity>(),            // body force
      entry<LinearDamping>(),      // body force, ESyS LinDamping
      entry<RotationalDamping>(),  // body force, ESyS RotDamping
      entry<LocalDamping>(),       // body force, Cundall
  };
  return models;
}

const ModelEntry* find_model(std::string_view name, ModelKind kind) {
  for (const auto& m : model_registry())
    if (m.name == name && m.kind == kind) return &m;
  return nullptr;
}

std::vector<std::string> model_names(ModelKind kind) {
  std::vector<std::string> names;
  for (const auto& m : model_registry())
    if (m.kind == kind) names.emplace_back(m.name);
  return names;
}

std::string field_names(Fields f) {
  static constexpr std::pair<Fields, const char*> kNames[] = {{kPosition, "position"},
                                                              {kVelocity, "velocity"},
                                                              {kForce, "force"},
                                                              {kRadius, "radius"},
                                                              {kInverseMass, "inverse_mass"},
                                                              {kId, "id"},
                                                              {kTag, "tag"},
                                                              {kAngularVelocity, "angular_velocity"},
                                                              {kTorque, "torque"},
                                                              {kOrientation, "orientation"}};
  std::string s;
  for (const auto& [bit, name] : kNames)
    if (f & bit) s += (s.empty() ? "" : ", ") + std::string(name);
  return s.empty() ? "none" : s;
}

std::string describe_models() {
  std::string s;
  for (const auto kind : {ModelKind::bond, ModelKind::pair, ModelKind::wall, ModelKind::body}) {
    s += fmt::format("{} models ({}):\n", kind_name(kind),
                     kind == ModelKind::wall   ? "[[walls]] or [[mesh_walls]] interaction = \"<name>\""
                     : kind == ModelKind::body ? "[[body_forces]] type = \"<name>\""
                                               : "[[interactions]] type = \"<name>\"");
    for (const auto& m : model_registry()) {
      if (m.kind != kind) continue;
      s += fmt::format("  {}\n    {}\n", m.name, m.summary);
      for (const auto& k : m.keys) s += fmt::format("    {:<14} {}\n", k.key, k.doc);
      if (!m.energy_term.empty()) s += fmt::format("    energy term: {}\n", m.energy_term);
      if (!m.dissipation_term.empty()) s += fmt::format("    dissipation term: {}\n", m.dissipation_term);
      s += fmt::format("    reads: {}; writes: {}; per-contact history: {}\n", field_names(m.reads),
                       field_names(m.writes),
                       m.history_bytes ? fmt::format("{} B", m.history_bytes) : std::string("none"));
    }
  }
  return s;
}

void refuse_single_precision(const Scene& scene) {
  for (const auto* groups : {&scene.bonds, &scene.contacts})
    for (const auto& g : *groups) {
      const auto* m = find_model(g.model, g.kind);
      const std::string_view why = m && m->float_problem ? m->float_problem(g.params) : std::string_view{};
      if (why.empty()) continue;
      throw InputError(fmt::format(
          "[[interactions]] \"{}\" (type = \"{}\"): {} (run.precision = \"{}\"; --precision double "
          "overrides the scene's precision and --preset fast's float)",
          g.name, g.model, why, scene.precision == "double" ? "float" : scene.precision));
    }
}

template <class Real>
std::vector<std::unique_ptr<ForceCompute<Real>>> make_force_computes(const Scene& scene) {
  if constexpr (!std::is_same_v<Real, double>) refuse_single_precision(scene);
  std::vector<std::unique_ptr<ForceCompute<Real>>> out;
  const auto add = [&](std::string_view name, ModelKind kind, std::set<std::string_view>& made) {
    if (!made.insert(name).second) return;
    const auto* m = find_model(name, kind);
    if (!m) throw InputError(fmt::format("no {} model \"{}\" in this build", kind_name(kind), name));
    if constexpr (std::is_same_v<Real, double>)
      out.push_back(m->make_double(scene));
    else
      out.push_back(m->make_float(scene));
  };
  std::set<std::string_view> bonds, pairs, walls;
  for (const auto& g : scene.bonds) add(g.model, ModelKind::bond, bonds);
  // Bond groups index one driver's parameters (Bonds::group); a second bond model needs a driver that
  // skips the other's groups: refused until a second bond model exists.
  if (bonds.size() > 1) throw InputError("interactions: all bond groups must use the same bond model");
  for (const auto& g : scene.contacts) add(g.model, ModelKind::pair, pairs);
  for (const auto& w : scene.walls) add(w.model, ModelKind::wall, walls);
  // Mesh walls: one driver per wall model they use, after the planar walls' (checkpoints' model order).
  std::set<std::string_view> meshes;
  for (const auto& w : scene.mesh_walls) {
    if (!meshes.insert(w.model).second) continue;
    const auto* m = find_model(w.model, ModelKind::wall);
    if (!m || !m->make_mesh_double)
      throw InputError(fmt::format("no wall model \"{}\" in this build", w.model));
    if constexpr (std::is_same_v<Real, double>)
      out.push_back(m->make_mesh_double(scene));
    else
      out.push_back(m->make_mesh_float(scene));
  }
  std::set<std::string_view> bodies;
  for (const auto& b : scene.body_forces) add(b.model, ModelKind::body, bodies);
  return out;
}

template std::vector<std::unique_ptr<ForceCompute<double>>> make_force_computes<double>(const Scene&);
template std::vector<std::unique_ptr<ForceCompute<float>>> make_force_computes<float>(const Scene&);

}  // namespace basalt::solver
