// basalt-run: runs a scene (TOML) on the compute ranks.
//   mpirun -np N basalt-run scenes/wave.toml [--geometry FILE] [--steps N] [--output DIR] [--dims x,y,z]
//                                            [--quiet] [--force-dt]
// Rank 0 prints a progress line (step, steps/s, particle-steps/s, ETA) and a summary of the time per
// step split into phases. Field savers go to DIR/fields.csv (rank 0).
#include <mpi.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>
#include <memory>
#include <optional>

#include "basalt/io/geometry.hpp"
#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/output/field_sink.hpp"
#include "basalt/solver/parallel/communicator.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/simulation.hpp"
#include "basalt/version.hpp"

namespace fs = std::filesystem;
using namespace basalt::solver;

namespace {

std::array<int, 3> parse_dims(const std::string& s) {
  std::array<int, 3> d{0, 0, 0};
  if (s.empty()) return d;
  char c1 = 0, c2 = 0;
  int n = 0;
  if (std::sscanf(s.c_str(), "%d%c%d%c%d%n", &d[0], &c1, &d[1], &c2, &d[2], &n) != 5 || c1 != ',' || c2 != ',' ||
      static_cast<std::size_t>(n) != s.size() || d[0] < 1 || d[1] < 1 || d[2] < 1)
    throw InputError(fmt::format("--dims {}: expected three positive integers, e.g. --dims 2,1,1", s));
  return d;
}

int run(int argc, char** argv, MPI_Comm compute) {
  const Comm comm(compute);
  const bool root = comm.rank() == 0;
  CLI::App app{"basalt-run: parallel DEM solver (Basalt)"};
  std::string scene_file, geometry, output, dims_text;
  std::int64_t steps = -1;
  bool quiet = false, force_dt = false;
  app.add_option("scene", scene_file, "scene file (TOML, docs/scenes.md)")->required();
  app.add_option("--geometry", geometry, "geometry file (.h5 or .geo); overrides the scene's geometry.file");
  app.add_option("--steps", steps, "number of steps; overrides run.steps")->check(CLI::NonNegativeNumber);
  app.add_option("--output", output, "output folder; overrides output.directory");
  app.add_option("--dims", dims_text, "rank grid x,y,z (default: MPI_Dims_create)");
  app.add_flag("--quiet", quiet, "no progress line");
  app.add_flag("--force-dt", force_dt, "run even when dt exceeds the critical time step");
  app.set_version_flag("--version", std::string(basalt::kVersion));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (root) return app.exit(e);
    return e.get_exit_code();
  }

  Scene scene = parse_scene(scene_file);
  if (!geometry.empty()) scene.geometry = geometry;
  if (steps >= 0) scene.steps = steps;
  if (!output.empty()) scene.output_dir = output;
  if (!fs::exists(scene.geometry))
    throw InputError(fmt::format("{}: geometry file {} does not exist{}", scene_file, scene.geometry.string(),
                                 geometry.empty() ? " (geometry.file; --geometry overrides it)" : " (--geometry)"));
  RunOptions options;
  options.dims = parse_dims(dims_text);
  options.quiet = quiet;
  options.force_dt = force_dt;

  const auto t0 = std::chrono::steady_clock::now();
  std::unique_ptr<Simulation<double>> sim;
  {
    auto g = basalt::io::read_geometry(scene.geometry);
    if (root && (g.units.length != scene.units.length || g.units.time != scene.units.time ||
                 g.units.force != scene.units.force))
      fmt::print(stderr, "warning: the geometry declares units {}, {}, {}; the scene {}, {}, {}\n", g.units.length,
                 g.units.time, g.units.force, scene.units.length, scene.units.time, scene.units.force);
    sim = std::make_unique<Simulation<double>>(scene, std::move(g), compute, options);
  }
  const auto& st = sim->stability();
  if (root) {
    fmt::print("basalt-run {}: {} particles, {} bonds on {} rank(s) ({}x{}x{}), {} steps of dt = {} {}\n",
               basalt::kVersion, sim->total_particles(), sim->bond_count(), comm.size(), sim->decomposition().dims()[0],
               sim->decomposition().dims()[1], sim->decomposition().dims()[2], scene.steps, scene.dt, scene.units.time);
    if (st.dt_critical > 0)
      fmt::print("time step: dt = {:.3g} x critical step {:.4g} (2 sqrt(m_min/k_max), m_min = {:.4g}, k_max = {:.4g}); "
                 "safe fraction {}\n",
                 st.fraction, st.dt_critical, st.m_min, st.k_max, scene.dt_safety);
    if (st.warn)
      fmt::print(stderr, "warning: dt = {} is {:.3g} x the critical time step, above the safe fraction {}\n", scene.dt,
                 st.fraction, scene.dt_safety);
    if (sim->unassigned_bonds() > 0)
      fmt::print(stderr, "warning: {} bonds of the geometry match no bond interaction and exert no force\n",
                 sim->unassigned_bonds());
  } else {
    (void)sim->bond_count();
  }

  std::unique_ptr<FieldSink> sink;
  std::optional<std::string> sink_error;
  if (root && !scene.fields.empty()) {
    try {
      sink = std::make_unique<CsvFieldSink>(scene.output_dir);
      sink->begin(field_columns(scene));
    } catch (const std::exception& e) {
      sink_error = e.what();
    }
  }
  if (auto e = comm.agree_error(sink_error)) throw InputError(*e);

  const double startup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto t1 = std::chrono::steady_clock::now();
  sim->run(scene.steps, sink.get());
  const double loop = comm.max(std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());

  const auto& t = sim->times();
  const double n = std::max<double>(1, double(scene.steps));
  const double parts[5] = {comm.max(t.forces), comm.max(t.neighbor), comm.max(t.communication),
                           comm.max(t.integration), comm.max(t.output)};
  const double mem = comm.sum(double(sim->memory_bytes()));
  if (root) {
    const double ps = double(sim->total_particles()) * double(scene.steps) / std::max(loop, 1e-12);
    fmt::print("done: {} steps in {:.3f} s ({:.1f} steps/s, {:.3f} M particle-steps/s); start-up {:.3f} s; {} rebuilds\n",
               scene.steps, loop, double(scene.steps) / std::max(loop, 1e-12), ps * 1e-6, startup, sim->rebuilds());
    const char* names[5] = {"forces", "neighbour search", "communication", "integration", "output"};
    std::string line = "time per step:";
    for (int k = 0; k < 5; ++k)
      line += fmt::format(" {} {:.4f} ms ({:.1f} %){}", names[k], 1e3 * parts[k] / n,
                          100 * parts[k] / std::max(loop, 1e-12), k < 4 ? "," : "");
    fmt::print("{}\n", line);
    fmt::print("solver arrays: {:.1f} MB ({:.0f} bytes per particle)\n", mem / 1e6,
               mem / double(sim->total_particles()));
    if (sink) fmt::print("fields: {}\n", static_cast<CsvFieldSink*>(sink.get())->path().string());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  // The compute communicator: today all ranks; the I/O-ranks issue will split some off here.
  MPI_Comm compute = MPI_COMM_NULL;
  MPI_Comm_dup(MPI_COMM_WORLD, &compute);
  int code = 0;
  try {
    code = run(argc, argv, compute);
  } catch (const std::exception& e) {
    // Every error reaching here is raised alike on all ranks (scene, geometry, agreed run errors).
    if (rank == 0) fmt::print(stderr, "basalt-run: error: {}\n", e.what());
    code = 1;
  }
  MPI_Comm_free(&compute);
  MPI_Finalize();
  return code;
}
