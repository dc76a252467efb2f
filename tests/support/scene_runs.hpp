#pragma once
// Scenes the solver tests run: a scene from TOML text, run options without a progress line, a sink that keeps
// every field row in memory, a simulation built with its sink (the "build, sink, begin, run" of a test),
// random starting velocities by id, and how far one run's series strays from another's.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/solver/output/field_sink.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"

namespace basalt::test {

/// Scene from TOML text; geometry.file is a placeholder (tests pass the geometry in memory).
inline solver::Scene scene_from(const std::string& body) {
  return solver::parse_scene_text("[geometry]\nfile = \"unused.geo\"\n" + body, "test.toml", ".");
}

/// Run options with no progress line, on the rank grid `dims` ({0, 0, 0}: MPI_Dims_create chooses).
inline solver::RunOptions quiet(std::array<int, 3> dims = {0, 0, 0}) {
  solver::RunOptions opt;
  opt.dims = dims;
  opt.quiet = true;
  return opt;
}

/// Keeps every row: columns[c] -> values by step.
class MemorySink final : public solver::FieldSink {
 public:
  std::vector<std::string> columns;
  std::vector<std::int64_t> steps;
  std::vector<double> times;
  std::vector<std::vector<std::optional<double>>> rows;
  MemorySink() = default;
  /// Begun with the field columns of `scene`.
  explicit MemorySink(const solver::Scene& scene) { begin(solver::field_columns(scene)); }
  void begin(const std::vector<std::string>& c) override { columns = c; }
  void row(std::int64_t s, double t, const std::vector<std::optional<double>>& v) override {
    steps.push_back(s);
    times.push_back(t);
    rows.push_back(v);
  }
  void flush() override {}
  std::vector<double> column(std::size_t c) const {
    std::vector<double> out;
    for (const auto& r : rows) out.push_back(r[c].value_or(NAN));
    return out;
  }
};

/// A simulation of `scene` on `geometry` over `comm` and a MemorySink begun with the scene's field columns:
/// run(steps) fills the sink.
template <class Real = double>
struct FieldRun {
  solver::Simulation<Real> sim;
  MemorySink sink;
  FieldRun(const solver::Scene& scene, const io::Geometry& geometry, MPI_Comm comm,
           const solver::RunOptions& options = quiet())
      : sim(scene, geometry, comm, options), sink(scene) {}
  FieldRun& run(std::int64_t steps) {
    sim.run(steps, &sink);
    return *this;
  }
};

/// The field rows of `steps` steps of `scene` on `geometry` over `comm` (rank grid `dims`, no progress line).
template <class Real = double>
MemorySink run_fields(const solver::Scene& scene, const io::Geometry& geometry, MPI_Comm comm,
                      std::int64_t steps, std::array<int, 3> dims = {0, 0, 0}) {
  return std::move(FieldRun<Real>(scene, geometry, comm, quiet(dims)).run(steps).sink);
}

/// The index of the owned particle with id `id` in `p` (a failure, and 0, when this rank owns none).
template <class Real>
std::size_t index_of(const solver::Particles<Real>& p, std::int64_t id) {
  for (std::size_t i = 0; i < p.n_owned; ++i)
    if (p.id[i] == id) return i;
  ADD_FAILURE() << "no particle " << id;
  return 0;
}

/// id -> values(p, i) (a std::vector<double> of the same length for every particle) of every rank's owned
/// particles, gathered on every rank: a run's state to compare across runs and rank counts.
template <class Real, class Values>
std::map<std::int64_t, std::vector<double>> gather_by_id(const solver::Simulation<Real>& sim, Values values) {
  const auto& p = sim.particles();
  std::vector<double> mine;
  std::size_t width = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const std::vector<double> v = values(p, i);
    width = v.size();
    mine.push_back(double(p.id[i]));
    mine.insert(mine.end(), v.begin(), v.end());
  }
  if (sim.comm().size() > 1) width = static_cast<std::size_t>(sim.comm().max(double(width)));
  const auto all = sim.comm().size() > 1 ? sim.comm().all_gather(mine) : mine;
  std::map<std::int64_t, std::vector<double>> m;
  for (std::size_t k = 0; k + width + 1 <= all.size(); k += width + 1)
    m[std::int64_t(all[k])] =
        std::vector<double>(all.begin() + std::ptrdiff_t(k) + 1, all.begin() + std::ptrdiff_t(k + width) + 1);
  return m;
}

/// Gives every owned particle of `sim` the velocity drift + scale (hash_unit(3 id), hash_unit(3 id + 1),
/// hash_unit(3 id + 2)), random by id and so the same on any number of ranks, and tells `sim` its state
/// changed.
template <class Real>
void random_velocities(solver::Simulation<Real>& sim, double scale, std::array<double, 3> drift = {0, 0, 0}) {
  auto& p = sim.particles();
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const auto id = static_cast<std::uint64_t>(p.id[i]);
    p.vx[i] = Real(drift[0] + scale * hash_unit(3 * id));
    p.vy[i] = Real(drift[1] + scale * hash_unit(3 * id + 1));
    p.vz[i] = Real(drift[2] + scale * hash_unit(3 * id + 2));
  }
  sim.state_changed();
}

/// The largest |a[s] - ref[s]| / ref[s] over the steps s of `a` where ref[s] > floor * ref.back(): how far a
/// run's series (kinetic energy ...) strays from a reference run's, leaving out the first steps where the
/// reference is still rounding noise.
inline double worst_relative(const std::vector<double>& a, const std::vector<double>& ref, double floor) {
  double worst = 0;
  for (std::size_t s = 0; s < a.size(); ++s)
    if (ref[s] > floor * ref.back()) worst = std::max(worst, std::abs(a[s] - ref[s]) / ref[s]);
  return worst;
}

}  // namespace basalt::test
