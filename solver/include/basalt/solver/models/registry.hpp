#pragma once
// The models this build knows, by name (solver/src/models/registry.cpp: one line per model). The
// scene parser reads a model's keys through it, `basalt-run --list-models` prints it, and Simulation
// builds its list of force computes from it: nothing else names a model.
#include <any>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "basalt/solver/interactions/force_compute.hpp"
#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

struct ModelEntry {
  std::string_view name;
  ModelKind kind;
  std::string_view summary;
  std::span<const KeyDoc> keys;
  Fields reads, writes;
  std::size_t history_bytes;          ///< per contact (0: none)
  std::string_view energy_term;       ///< body forces: the ledger term of its potential energy ("" otherwise)
  std::string_view dissipation_term;  ///< the ledger term of the energy it dissipates ("" for none)
  std::any (*parse)(TableReader&);
  /// The stiffest spring of one group with these (parsed) parameters, at the largest radius.
  double (*max_stiffness)(const std::any& params, double rmax);
  std::unique_ptr<ForceCompute<double>> (*make_double)(const Scene&);
  std::unique_ptr<ForceCompute<float>> (*make_float)(const Scene&);
  /// Wall models: the driver of the scene's mesh walls that use it (null for other kinds).
  std::unique_ptr<ForceCompute<double>> (*make_mesh_double)(const Scene&) = nullptr;
  std::unique_ptr<ForceCompute<float>> (*make_mesh_float)(const Scene&) = nullptr;
  /// Why a group with these parameters cannot run in single precision, or "" (Model::float_problem; null:
  /// the model runs in float with any parameters).
  std::string_view (*float_problem)(const std::any& params) = nullptr;
};

/// Every model, in the order --list-models prints them.
const std::vector<ModelEntry>& model_registry();
/// The model called `name` of this kind, or null.
const ModelEntry* find_model(std::string_view name, ModelKind kind);
/// Names of the models of one kind (the allowed values of a scene's type key).
std::vector<std::string> model_names(ModelKind kind);
/// The --list-models text: each model with its keys, the fields it reads and writes, its history.
std::string describe_models();
/// Names of the fields in a bit set, comma-separated.
std::string field_names(Fields f);

/// Throws InputError naming the first interaction group whose model cannot compute it in single precision
/// (run.precision "float" or "mixed": Simulation<float>), and why. basalt-run checks before it reads the
/// geometry; make_force_computes<float> checks again for other callers.
void refuse_single_precision(const Scene& scene);

/// One force compute per model the scene uses: bond models first, then pair models (in the order the
/// scene first names them), then wall models, then body forces. Throws InputError for combinations not
/// supported.
template <class Real>
std::vector<std::unique_ptr<ForceCompute<Real>>> make_force_computes(const Scene& scene);

}  // namespace basalt::solver
