// basalt-run: runs a scene (TOML) on P compute ranks with Q dedicated I/O ranks.
//   mpirun -np P+Q basalt-run scenes/wave.toml [--io-ranks Q] [--geometry FILE] [--steps N] [--output DIR]
//          [--dims x,y,z] [--checkpoint-every N] [--frames-every N] [--fields-every N]
//          [--restart FILE|DIR [--whole-checkpoint]] [--balance none|count|pairs|time]
//          [--balance-threshold X] [--quiet] [--force-dt]
//          [--render-every N [--render SPEC]]
// The only code that touches MPI_COMM_WORLD: it creates the output folder (world rank 0, a failure
// stops every rank before anything starts) and splits the world into compute and I/O ranks. Compute
// rank 0 prints progress, a summary of the time per step and the output report (docs/io-ranks.md).
#include <fmt/format.h>
#include <mpi.h>
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "basalt/io/checkpoint.hpp"
#include "basalt/io/checkpoint_rows.hpp"
#include "basalt/io/geometry.hpp"
#include "basalt/io/geometry_rows.hpp"
#include "basalt/io/io_ranks.hpp"
#if !defined(BASALT_WITH_VTK)
#error "BASALT_WITH_VTK must be 0 or 1 (solver/CMakeLists.txt defines it for basalt-run)"
#endif
#if BASALT_WITH_VTK
#include "basalt/io/vtk_frame_writer.hpp"
#endif
#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/core/stop_request.hpp"
#include "basalt/solver/models/registry.hpp"
#include "basalt/solver/parallel/communicator.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/simulation.hpp"
#include "basalt/solver/stages.hpp"
#include "basalt/version.hpp"
#include "client_sink.hpp"
#include "geometry_input.hpp"
#include "output_folder.hpp"
#include "picture_module.hpp"
#include "process_setup.hpp"
#include "rank_spread.hpp"
#include "restart_support.hpp"
#include "run_start.hpp"

namespace fs = std::filesystem;
using namespace basalt::solver;
namespace io = basalt::io;

namespace {

struct Cli {
  std::string scene_file, geometry, output, dims_text, restart, precision, preset;
  std::int64_t steps = -1;
  bool quiet = false, force_dt = false, force_overlap = false, whole_geometry = false,
       whole_checkpoint = false;
  int io_ranks = 0;
  std::int64_t checkpoint_every = -1, frames_every = -1, fields_every = -1, render_every = -1;
  std::optional<std::string> render;
  double throttle_mbps = 0;
  int frames_in_flight = 0;
  std::string balance;
  double balance_threshold = 0;
};

#if !BASALT_WITH_VTK
/// A build without VTK (BASALT_WITH_VTK off, solver/CMakeLists.txt) writes no VTK frames and draws no
/// pictures: asking for either (command line or scene) stops every rank before anything starts, in one line
/// that names the option, why and the way round. Every rank raises it alike (it depends on the scene and
/// options only).
void refuse_without_vtk(const Scene& scene, const Cli& cli) {
  const auto refuse = [](const std::string& what, std::int64_t every, const char* needs,
                         const char* instead) {
    throw InputError(fmt::format("{} {}: {} VTK, and this build has none (BASALT_WITH_VTK=OFF: {}); {}", what,
                                 every, needs, BASALT_WITHOUT_VTK_REASON, instead));
  };
  if (scene.frames_every > 0)
    refuse(cli.frames_every >= 0 ? "--frames-every" : "output.frames_every", scene.frames_every,
           "VTK frames need",
           "write checkpoints (--checkpoint-every N) and open ckpt_series.xmf in ParaView instead");
  if (scene.render_every > 0)
    refuse(cli.render_every >= 0 ? "--render-every" : "output.render_every", scene.render_every,
           "in-situ pictures need",
           "write checkpoints (--checkpoint-every N), open ckpt_series.xmf in ParaView, or draw them with a "
           "basalt-view built with VTK");
}
#endif

/// User + system CPU seconds of this process.
double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// CLI11's NonNegativeNumber/PositiveNumber print their bound, the largest double, in 309 digits.
const CLI::Validator kNonNegative(
    [](const std::string& text) {
      double v = 0;
      if (!CLI::detail::lexical_cast(text, v) || !(v >= 0)) return "must be >= 0, got " + text;
      return std::string{};
    },
    ">= 0");
const CLI::Validator kPositive(
    [](const std::string& text) {
      double v = 0;
      if (!CLI::detail::lexical_cast(text, v) || !(v > 0)) return "must be > 0, got " + text;
      return std::string{};
    },
    "> 0");

// An empty path would silently mean the scene's setting (the options are overrides) or no path at all.
const CLI::Validator kNonEmptyPath(
    [](const std::string& text) {
      return text.empty() ? std::string("is empty: name a path, or leave the option out to use the scene's")
                          : std::string{};
    },
    "PATH");

std::array<int, 3> parse_dims(const std::string& s) {
  std::array<int, 3> d{0, 0, 0};
  if (s.empty()) return d;
  char c1 = 0, c2 = 0;
  int n = 0;
  if (std::sscanf(s.c_str(), "%d%c%d%c%d%n", &d[0], &c1, &d[1], &c2, &d[2], &n) != 5 || c1 != ',' ||
      c2 != ',' || static_cast<std::size_t>(n) != s.size() || d[0] < 1 || d[1] < 1 || d[2] < 1)
    throw InputError(fmt::format("--dims {}: expected three positive integers, e.g. --dims 2,1,1", s));
  return d;
}

std::string mb(std::uint64_t bytes) { return fmt::format("{:.2f} MB", double(bytes) * 1e-6); }

/// "fields: position, velocity, ... = 112 B/particle" (and the contact history per contact): what the
/// scene allocates.
template <class Real>
std::string fields_line(const Simulation<Real>& sim) {
  std::string names;
  std::size_t bytes = 0;
  for (const auto& [name, b] : sim.particles().field_bytes()) {
    names += (names.empty() ? "" : ", ") + name;
    bytes += b;
  }
  std::string line = fmt::format("fields: {} = {} B/particle", names, bytes);
  std::string history;
  for (const auto& c : sim.force_computes())
    if (c->history_bytes() > 0)
      history += fmt::format("{}{} {} B", history.empty() ? "" : ", ", c->model(), c->history_bytes());
  line +=
      history.empty() ? "; contact history: none" : fmt::format("; contact history: {} per contact", history);
  return line;
}

void print_report(const io::OutputReport& r, int n_io) {
  auto kind = [](const char* name, const io::OutputKindReport& k) {
    return fmt::format("  {:<12} {:>5} files {:>12}  write {:8.3f} s\n", name, k.files, mb(k.bytes),
                       k.write_seconds);
  };
  std::string text = fmt::format("output ({}):\n", n_io > 0 ? fmt::format("{} I/O rank(s)", n_io)
                                                            : std::string("written by the compute ranks"));
  text += kind("checkpoints", r.checkpoints) + kind("frames", r.frames) + kind("fields", r.fields);
  if (r.pictures_due > 0) {
    text += fmt::format(
        "  {:<12} {:>5} files {:>12}  draw  {:8.3f} s ({:.3f} s per picture, longest {:.3f} s); {} of {} "
        "drawn, {} skipped",
        "pictures", r.pictures.files, mb(r.pictures.bytes), r.pictures.write_seconds,
        r.pictures.write_seconds / double(std::max<std::uint64_t>(1, r.pictures.files)),
        r.picture_max_seconds, r.pictures.files, r.pictures_due, r.pictures_skipped);
    if (r.pictures_skipped > 0)
      text +=
          fmt::format(" (steps {}: {})", r.pictures_skipped_steps,
                      r.error ? "not drawn after the error below"
                              : "a newer frame came while each waited to be drawn; the I/O rank draws slower "
                                "than pictures are asked for");
    text += "\n";
  }
  text += fmt::format("  compute ranks waited {:.4f} s for output", r.compute_wait_seconds);
  if (n_io > 0)
    text += fmt::format("; I/O rank CPU time {:.3f} s over {:.3f} s wall ({:.1f} %)", r.io_cpu_seconds,
                        r.io_wall_seconds, 100 * r.io_cpu_seconds / std::max(r.io_wall_seconds, 1e-12));
  fmt::print("{}\n", text);
}

template <class Real>
int run_compute(const Cli& cli, Scene& scene, const io::RankLayout& layout, io::OutputConfig cfg,
                const io::VtkFrameWriter& vtk, const io::CheckpointHeader* header,
                const io::Checkpoint* whole, std::optional<io::CheckpointFile>* rows_file,
                const fs::path& ckpt_file, const basalt::solver::StageProgress* stage_progress) {
  const Comm comm(layout.compute);
  const bool root = comm.rank() == 0;
  RunOptions options;
  options.dims = parse_dims(cli.dims_text);
  options.quiet = cli.quiet;
  options.force_dt = cli.force_dt;
  options.force_overlap = cli.force_overlap;

  const auto t0 = std::chrono::steady_clock::now();
  io::RunInfo info;
  const auto sim = basalt::run::start_simulation<
      Real>(scene, layout, cfg, vtk, info, [&](io::RunInfo& run_info) -> std::unique_ptr<Simulation<Real>> {
    std::unique_ptr<Simulation<Real>> built;
    if (header) {
      const auto restart_layout = basalt::run::restart_layout_of(*header, ckpt_file);
      if (whole) {  // --whole-checkpoint: the former restart, kept as the check of the one below
        built = std::make_unique<Simulation<Real>>(scene, *whole, restart_layout, layout.compute, options);
      } else {
        // Each compute rank reads a slice of the checkpoint's rows and the ranks route them to their
        // owners (docs/solver.md, "Restart"); the file is closed once they have.
        built =
            std::make_unique<Simulation<Real>>(scene, **rows_file, restart_layout, layout.compute, options);
        rows_file->reset();
      }
      const auto& g = header->run.geometry;
      run_info.box_min = g.box_min;
      run_info.box_max = g.box_max;
      run_info.periodic = g.periodic;
      run_info.units = g.units;
      if (std::getenv("BASALT_DEBUG_LOAD")) {
        const auto& ls = built->load_stats();
        fmt::print(
            "restart: compute rank {} read {} particle rows and {} bond rows of {} and {}; holds {} owned "
            "particles, {} bonds\n",
            comm.rank(), ls.particle_rows, ls.bond_rows, header->particles, header->bonds, ls.owned,
            ls.bonds);
        std::fflush(stdout);
      }
      return built;
    }
    auto rows = basalt::run::open_geometry(scene, cfg.dir, comm, cli.quiet, run_info);
    const io::GeometryHeader h = rows->header();
    if (cli.whole_geometry) {  // the former start-up, kept as the check of the sliced one
      const fs::path file = rows->path();
      rows.reset();
      built = std::make_unique<Simulation<Real>>(scene, io::read_geometry(file), layout.compute, options);
    } else {
      built = std::make_unique<Simulation<Real>>(scene, *rows, layout.compute, options);
    }
    if (std::getenv("BASALT_DEBUG_LOAD")) {
      const auto& ls = built->load_stats();
      fmt::print(
          "load: compute rank {} read {} particle rows and {} bond rows of {} and {}; holds {} owned "
          "particles, {} far bond ends, {} bonds\n",
          comm.rank(), ls.particle_rows, ls.bond_rows, h.particles, h.bonds, ls.owned, ls.ghost_ends,
          ls.bonds);
      std::fflush(stdout);
    }
    return built;
  });

  std::int64_t steps = scene.steps;
  for (std::size_t k = 0; k < scene.stages.size(); ++k)
    steps = (k ? steps : 0) + scene.stages[k].steps;  // at most
  if (header) steps = cli.steps >= 0 ? cli.steps : std::max<std::int64_t>(0, scene.steps - header->run.step);
  const auto& st = sim->stability();
  const double imbalance_start = sim->imbalance();
  const auto balance_setting = [&] {
    if (scene.balance == "none") return std::string("run.balance = \"none\"");
    return scene.balance == "count" || scene.balance == "pairs"
               ? fmt::format("run.balance = \"{}\", threshold {}", scene.balance, scene.balance_limit())
               : fmt::format("run.balance = \"time\", threshold {}, every {} steps", scene.balance_limit(),
                             scene.balance_every);
  };
  if (root) {
    fmt::print(
        "basalt-run {}: {} particles, {} bonds on {} compute rank(s) ({}x{}x{}) + {} I/O rank(s), {} steps "
        "of "
        "dt = {} {} in {}{}\n",
        basalt::kVersion, sim->total_particles(), sim->bond_count(), comm.size(),
        sim->decomposition().dims()[0], sim->decomposition().dims()[1], sim->decomposition().dims()[2],
        layout.n_io, steps, scene.dt, scene.units.time, scene.precision,
        header ? fmt::format(", continuing from step {} ({})", header->run.step, ckpt_file.string())
               : std::string());
    if (st.dt_critical > 0) {
      fmt::print(
          "critical step: {:.4g} {} (2/omega_max, {} Lanczos iterations on the network: {:.4g}; one new "
          "contact "
          "of the lightest particle: {:.4g}); bound {:.4g} (omega^2 <= max_i 2 sum_j k_ij / m_i); former "
          "estimate 2 sqrt(m_min/k_max) = {:.4g} (m_min = {:.4g}, k_max = {:.4g}){}{}\n",
          st.dt_critical, scene.units.time, st.iterations, st.dt_power, st.dt_contact, st.dt_bound,
          st.dt_pair, st.m_min, st.k_max,
          std::isfinite(st.dt_broken)
              ? fmt::format("; breakable bonds as stiff as the contacts: {:.4g}", st.dt_broken)
              : std::string(),
          st.retries > 0 ? fmt::format("; perturbation {:.3g}, {}x smaller than the first, which broke bonds",
                                       st.perturbation, 1 << (3 * st.retries))
                         : std::string());
      fmt::print("time step: dt = {:.6g} {} = {:.3g} x critical{}; safe fraction {}\n", scene.dt,
                 scene.units.time, st.fraction,
                 st.dt_fraction > 0 ? fmt::format(" (run.dt_fraction = {})", st.dt_fraction) : "",
                 scene.dt_safety);
    }
    for (const auto& w : sim->step_warnings()) fmt::print(stderr, "warning: {}\n", w);
    fmt::print("{}\n", fields_line(*sim));
    if (comm.size() > 1)
      fmt::print("balance: max/mean particles per rank {:.3f} at start ({})\n", imbalance_start,
                 balance_setting());
    if (sim->unassigned_bonds() > 0)
      fmt::print(stderr, "warning: {} bonds of the geometry match no bond interaction and exert no force\n",
                 sim->unassigned_bonds());
  } else {
    (void)sim->bond_count();
  }

  io::OutputClient client(layout, cfg, info, vtk);
  basalt::run::ClientSink sink(client, cfg.continue_on_error);
  // Checkpoint steps are restart points: the lists are rebuilt there in canonical order.
  const double startup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto t1 = std::chrono::steady_clock::now();
  const double cpu0 = cpu_seconds();
  // The phases of the loop alone: the start-up's first rebuild and force evaluation are timed too.
  const basalt::solver::PhaseTimes before = sim->times();
  const std::array<double, 4> kinds_before = sim->force_seconds_by_kind();
  std::optional<std::string> run_error;
  if (client.error() && !cfg.continue_on_error) {
    run_error = *client.error();
  } else {
    try {
      if (scene.stages.empty()) {
        sim->run(steps, sink);
      } else {
        steps = basalt::solver::run_stages(
            *sim, sink, scene.stages,
            [&](const auto& stage, const auto& r) {
              if (root) fmt::print("{}\n", basalt::solver::describe(stage, r));
            },
            stage_progress);
      }
    } catch (const std::exception& e) {
      run_error = e.what();  // raised alike on every compute rank
    }
  }
  const double loop_local = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  const double cpu_local = cpu_seconds() - cpu0;
  const io::OutputReport report = client.finish();
  // An error the I/O ranks reported after the last check still fails the run (unless "continue").
  if (!run_error && report.error && !cfg.continue_on_error)
    run_error = fmt::format("output failed (reported at the end of the run): {}", *report.error);
  if (run_error) {
    if (root) print_report(report, layout.n_io);
    throw RunError(*run_error);
  }
  const double loop = comm.max(loop_local);
  const double cpu = comm.max(cpu_local);

  const auto& after = sim->times();
  const basalt::solver::PhaseTimes t{after.forces - before.forces, after.neighbor - before.neighbor,
                                     after.communication - before.communication,
                                     after.integration - before.integration, after.output - before.output};
  const double n = std::max<double>(1, double(steps));
  const double parts[basalt::run::kPhases] = {comm.max(t.forces), comm.max(t.neighbor),
                                              comm.max(t.communication), comm.max(t.integration),
                                              comm.max(t.output)};
  const std::vector<double> by_rank =
      comm.size() > 1 ? comm.all_gather({t.forces, t.neighbor, t.communication, t.integration, t.output})
                      : std::vector<double>{};
  // The forces phase by model kind (each kind's largest time over the ranks), for the roofline
  // (tools/bench/roofline.py): the kinds' sum is the forces phase less its bookkeeping (zeroing, fixed
  // particles, the ghost poke).
  std::string kind_line = "forces by model kind:";
  for (std::size_t k = 0; k < 4; ++k) {
    const double s = comm.max(sim->force_seconds_by_kind()[k] - kinds_before[k]);
    kind_line +=
        fmt::format(" {} {:.4f} ms{}", basalt::solver::kind_name(static_cast<basalt::solver::ModelKind>(k)),
                    1e3 * s / n, k + 1 < 4 ? "," : "");
  }
  const double mem = comm.sum(double(sim->memory_bytes()));
  const double imbalance_end = sim->imbalance();
  if (root) {
    const double ps = double(sim->total_particles()) * double(steps) / std::max(loop, 1e-12);
    fmt::print(
        "done: {} steps in {:.3f} s ({:.1f} steps/s, {:.3f} M particle-steps/s); start-up {:.3f} s; {} "
        "rebuilds\n",
        steps, loop, double(steps) / std::max(loop, 1e-12), ps * 1e-6, startup, sim->rebuilds());
    fmt::print("cpu time of the loop: {:.3f} s per rank (max), {:.0f} % of the wall time{}\n", cpu,
               100 * cpu / std::max(loop, 1e-12),
               cpu < 0.8 * loop ? ": the machine is shared, the wall time is inflated" : "");
    std::string line = "time per step:";
    for (int k = 0; k < basalt::run::kPhases; ++k)
      line += fmt::format(" {} {:.4f} ms ({:.1f} %){}", basalt::run::kPhaseNames[static_cast<std::size_t>(k)],
                          1e3 * parts[k] / n, 100 * parts[k] / std::max(loop, 1e-12),
                          k + 1 < basalt::run::kPhases ? "," : "");
    fmt::print("{}\n", line);
    fmt::print("{}\n", kind_line);
    if (comm.size() > 1) fmt::print("{}", basalt::run::rank_spread(by_rank, n));
    fmt::print("solver arrays: {:.1f} MB ({:.0f} bytes per particle)\n", mem / 1e6,
               mem / double(sim->total_particles()));
    if (comm.size() > 1)
      fmt::print(
          "balance: max/mean particles per rank {:.3f} at start, {:.3f} at the end; {} re-balance(s) ({})\n",
          imbalance_start, imbalance_end, sim->rebalances(), balance_setting());
    print_report(report, layout.n_io);
    if (cfg.fields_every > 0) fmt::print("fields: {}\n", (cfg.dir / "fields.csv").string());
    if (report.error)
      fmt::print(stderr, "basalt-run: warning: output failed (on_error = \"continue\"): {}\n", *report.error);
  }
  return 0;
}

#if BASALT_WITH_VTK
constexpr const char* kFramesHelp = "VTK frame every N steps (0 = off)";
constexpr const char* kRenderHelp =
    "in-situ PNG picture every N steps, drawn by I/O rank 0 while the run goes on (needs --io-ranks "
    ">= 1; 0 = off; docs/io-ranks.md)";
#else
constexpr const char* kFramesHelp =
    "VTK frame every N steps (0 = off); not in this build (BASALT_WITH_VTK=OFF)";
constexpr const char* kRenderHelp =
    "in-situ PNG picture every N steps (0 = off); not in this build (BASALT_WITH_VTK=OFF)";
#endif

int run_world(int argc, char** argv) {
  int world_rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &world_rank);
  const bool world_root = world_rank == 0;
  Cli cli;
  CLI::App app{"basalt-run: parallel DEM solver (Basalt)"};
  app.add_option("scene", cli.scene_file, "scene file (TOML, docs/scenes.md)")->required();
  app.add_option("--geometry", cli.geometry,
                 "geometry file (.h5 or .geo); overrides the scene's geometry.file")
      ->check(kNonEmptyPath);
  app.add_option("--steps", cli.steps, "number of steps; overrides run.steps (with --restart: steps to add)")
      ->check(kNonNegative);
  app.add_option("--output", cli.output, "output folder; overrides output.directory")->check(kNonEmptyPath);
  app.add_option("--dims", cli.dims_text,
                 "compute-rank grid x,y,z (default: the least cut area, docs/solver.md)");
  app.add_option("--io-ranks", cli.io_ranks,
                 "dedicated I/O ranks among the mpirun ranks (0: compute ranks write)")
      ->check(kNonNegative);
  app.add_option("--checkpoint-every", cli.checkpoint_every, "HDF5 checkpoint every N steps (0 = off)")
      ->check(kNonNegative);
  app.add_option("--frames-every", cli.frames_every, kFramesHelp)->check(kNonNegative);
  app.add_option("--fields-every", cli.fields_every, "every field saver every N steps (0 = off)")
      ->check(kNonNegative);
  app.add_option("--render-every", cli.render_every, kRenderHelp)->check(kNonNegative);
  app.add_option(
      "--render", cli.render,
      "the pictures' settings: KEY=VALUE,... with keys color, cut, view, range, size, as basalt-view "
      "render's options (e.g. \"color=velocity_z,cut=y\"); overrides output.render");
  app.add_option("--restart", cli.restart,
                 "continue from a checkpoint, or from the latest complete one in a folder");
  app.add_option("--frames-in-flight", cli.frames_in_flight, "frames a compute rank may have posted (bound)")
      ->check(kPositive);
  app.add_option("--throttle-io-mbps", cli.throttle_mbps,
                 "benchmark only: make output storage this slow (MB/s)")
      ->check(kNonNegative);
  app.add_option("--preset", cli.preset,
                 "named accuracy/speed setting (docs/stability.md): fast (float, dt_fraction 0.5), balanced "
                 "(double, 0.25), reference (double, 0.05); overrides run.dt, run.dt_fraction, run.precision")
      ->check(CLI::IsMember({"fast", "balanced", "reference"}));
  app.add_option("--precision", cli.precision,
                 "floating-point type of the solver: double, float or mixed (float offsets from the "
                 "geometry's centre, compensated drift); overrides run.precision")
      ->check(CLI::IsMember({"double", "float", "mixed"}));
  app.add_option(
         "--balance", cli.balance,
         "load balancing of the rank grid: none (even cuts), count (cuts moved at rebuilds by particle "
         "count), pairs (by particle count weighted by listed pairs, bonds and walls) or time (cuts moved "
         "by measured compute time; docs/solver.md); overrides run.balance")
      ->check(CLI::IsMember({"none", "count", "pairs", "time"}));
  app.add_option(
         "--balance-threshold", cli.balance_threshold,
         "re-balance when the busiest rank holds more than this x the mean particles, work with --balance "
         "pairs, or compute time with --balance time (>= 1); overrides run.balance_threshold")
      ->check(CLI::Range(1.0, 1e300));
  app.add_flag("--quiet", cli.quiet, "no progress line");
  app.add_flag("--whole-geometry", cli.whole_geometry,
               "every compute rank reads the whole geometry file (the former start-up; a check of the "
               "sliced reading, which gives the same run)");
  app.add_flag(
      "--whole-checkpoint", cli.whole_checkpoint,
      "with --restart: every compute rank reads the whole checkpoint (the former restart; a check of the "
      "sliced reading, which gives the same run)");
  app.add_flag("--force-dt", cli.force_dt, "run even when dt exceeds the critical time step");
  app.add_flag("--force-overlap", cli.force_overlap,
               "start even when particles overlap by more than half a radius (each other or a wall)");
  app.set_version_flag("--version", std::string(basalt::kVersion));
  app.add_flag_callback(
      "--list-models",
      [world_root] {
        if (world_root) fmt::print("{}", describe_models());
        throw CLI::Success();
      },
      "print every model this build knows (scene keys, particle fields, contact history) and exit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (world_root) return app.exit(e);
    return e.get_exit_code();
  }

  Scene scene = parse_scene(cli.scene_file);
  if (!cli.geometry.empty()) scene.geometry = cli.geometry;
  if (cli.steps >= 0) scene.steps = cli.steps;
  if (!cli.output.empty()) scene.output_dir = cli.output;
  if (cli.checkpoint_every >= 0) scene.checkpoint_every = cli.checkpoint_every;
  if (cli.frames_every >= 0) scene.frames_every = cli.frames_every;
  if (cli.fields_every == 0) scene.fields.clear();
  if (cli.fields_every > 0)
    for (auto& f : scene.fields) f.every = cli.fields_every;
  if (cli.frames_in_flight > 0) scene.frames_in_flight = cli.frames_in_flight;
  // In-situ pictures: the spec is checked here on every rank, before anything starts.
  if (cli.render_every >= 0) scene.render_every = cli.render_every;
  if (cli.render) scene.render = *cli.render;
#if !BASALT_WITH_VTK
  refuse_without_vtk(scene, cli);
#endif
  io::RenderSpec render_spec;
  try {
    render_spec = io::parse_render_spec(scene.render, cli.render ? "--render" : "output.render");
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  if (cli.render && scene.render_every == 0)
    throw InputError("--render: no pictures asked for: give --render-every N (or output.render_every)");
  if (scene.render_every > 0 && cli.io_ranks == 0)
    throw InputError(fmt::format(
        "{} {}: in-situ pictures need an I/O rank (--io-ranks 1 or more): I/O rank 0 draws them while the "
        "compute ranks go on, which never wait for a picture; without I/O ranks, write checkpoints and draw "
        "them afterwards (basalt-view render out/ckpt_*.h5 -o pictures/)",
        cli.render_every > 0 ? "--render-every" : "output.render_every", scene.render_every));
  if (!scene.stages.empty() && cli.steps >= 0)
    throw InputError(fmt::format(
        "{}: --steps: the scene runs [[stages]], whose steps = N say how long each runs", cli.scene_file));
  if (!cli.preset.empty()) {  // docs/stability.md, "Presets": the error and speed measured for each
    scene.precision = cli.preset == "fast" ? "float" : "double";
    scene.dt = 0;
    scene.dt_fraction = cli.preset == "fast" ? 0.5 : cli.preset == "balanced" ? 0.25 : 0.05;
  }
  if (!cli.precision.empty()) scene.precision = cli.precision;
  if (scene.precision != "double") {
    try {
      basalt::solver::refuse_single_precision(scene);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: {}", cli.scene_file, e.what()));
    }
  }
  if (!cli.balance.empty()) scene.balance = cli.balance;
  if (cli.balance_threshold > 0) scene.balance_threshold = cli.balance_threshold;

  // A restart reads its checkpoint's header on every rank (so that a bad one stops all ranks alike, early);
  // the compute ranks read its rows in slices (or, with --whole-checkpoint, every rank reads it whole here).
  std::optional<io::Checkpoint> ckpt;
  std::optional<io::CheckpointFile> ckpt_rows;
  std::optional<io::CheckpointHeader> header;
  std::optional<basalt::solver::StageProgress> stage_progress;  ///< a staged run's restart
  fs::path ckpt_file;
  if (!cli.restart.empty()) {
    ckpt_file = basalt::run::resolve_restart(cli.restart, world_root);
    try {
      if (cli.whole_checkpoint) {
        ckpt = io::read_checkpoint(ckpt_file);
        header = io::header_of(*ckpt);
      } else {
        ckpt_rows.emplace(ckpt_file);
        header = ckpt_rows->header();
      }
    } catch (const std::exception& e) {
      throw InputError(fmt::format("--restart: {}", e.what()));
    }
    basalt::run::check_same_scene(*header, ckpt_file, scene);
    basalt::run::check_same_precision(*header, ckpt_file, scene.precision);
    if (scene.dt_fraction > 0) scene.dt = header->run.dt;  // the run's step, chosen at its start
    if (!scene.stages.empty()) {
      // A staged run goes on in the stage it was in, with the changes of the stages begun replayed into the
      // scene (the walls taken away or set moving, fixed tags, dt and the clock): stages.hpp.
      const auto& attrs = header->run.geometry.attributes;
      const auto it = attrs.find("stage_first_steps");
      if (it == attrs.end())
        throw InputError(
            fmt::format("--restart: {} has no attribute stage_first_steps: it was not written by a run "
                        "of [[stages]] (by an older basalt-run, or by a scene without stages)",
                        ckpt_file.string()));
      try {
        stage_progress = basalt::solver::StageProgress::parse(it->second, scene.stages.size());
        if (scene.dt_fraction > 0)
          for (std::size_t k = 0; k < stage_progress->first_steps.size(); ++k)
            if (scene.stages[k].dt > 0)
              throw InputError(
                  fmt::format("stage {} changed dt in a run whose dt was run.dt_fraction x the critical "
                              "step: its clock cannot be replayed; give run.dt",
                              scene.stages[k].name));
        basalt::solver::replay_stages(scene, *stage_progress);
      } catch (const InputError& e) {
        throw InputError(fmt::format("--restart: {}: {}", ckpt_file.string(), e.what()));
      }
    }
    (void)basalt::run::restart_layout_of(*header, ckpt_file);
  } else if (cli.whole_checkpoint) {
    throw InputError("--whole-checkpoint: no --restart to read whole");
  } else if (!fs::exists(scene.geometry)) {
    throw InputError(
        fmt::format("{}: geometry file {} does not exist{}", cli.scene_file, scene.geometry.string(),
                    cli.geometry.empty() ? " (geometry.file; --geometry overrides it)" : " (--geometry)"));
  } else if (!fs::is_directory(scene.geometry)) {  // (a folder is named as one when it is opened)
    try {  // read by its extension: any other one is named before anything starts, not "not an HDF5 file"
      (void)io::geometry_format(scene.geometry);
    } catch (const io::FormatError& e) {
      throw InputError(fmt::format("{}: {}: {}", cli.scene_file,
                                   cli.geometry.empty() ? "geometry.file" : "--geometry", e.what()));
    }
  }

  basalt::run::prepare_output_folder(scene.output_dir, MPI_COMM_WORLD);
  if (header && world_root && !scene.fields.empty()) {
    const fs::path csv = scene.output_dir / "fields.csv";
    const auto last = basalt::run::truncate_fields(csv, header->run.step);
    std::int64_t every = std::numeric_limits<std::int64_t>::max();
    for (const auto& f : scene.fields) every = std::min(every, f.every);
    // A checkpoint written before the rows up to its step reached the file (basalt-runs before the rows
    // were handed over first, or a crash of the machine): say so rather than leave a silent gap.
    if (last && *last + every <= header->run.step)
      fmt::print(stderr,
                 "basalt-run: warning: {} ends at step {}, before the checkpoint's step {}: the rows between "
                 "were lost when the run stopped; the restarted run appends from step {}\n",
                 csv.string(), *last, header->run.step, header->run.step + 1);
  }

  io::OutputConfig cfg;
  cfg.dir = scene.output_dir;
  cfg.checkpoint_every = scene.checkpoint_every;
  cfg.frames_every = scene.frames_every;
  cfg.fields_every = scene.fields.empty() ? 0 : 1;  // the solver decides which savers are due
  cfg.field_names = field_columns(scene);
  cfg.max_frames_in_flight = static_cast<int>(scene.frames_in_flight);
  cfg.continue_on_error = scene.output_continue_on_error;
  cfg.throttle_mb_per_s = cli.throttle_mbps;
  cfg.append_fields = header.has_value();
  cfg.render_every = scene.render_every;
#if BASALT_WITH_VTK
  const auto vtk = io::make_vtk_frame_writer(
      io::Units{scene.units.length, scene.units.time, scene.units.force, io::Units{}.mass},
      header ? header->run.time : -1.0);
#else
  const io::VtkFrameWriter vtk;  // none: VTK frames were refused above (refuse_without_vtk)
#endif

  io::RankLayout layout;
  try {
    layout = io::split_ranks(MPI_COMM_WORLD, cli.io_ranks);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  struct Free {
    io::RankLayout& l;
    ~Free() { io::free_layout(l); }
  } free_layout{layout};
  if (layout.is_io) {
    ckpt_rows.reset();
    ckpt.reset();
    // I/O ranks print nothing but errors (compute rank 0 prints the report). I/O rank 0 draws the
    // pictures: only it loads the render module (VTK rendering, OpenGL, X), and only when asked.
    io::Pictures pictures;
    if (cfg.render_every > 0 && layout.world_rank == layout.n_compute)
      pictures = basalt::run::load_picture_module(render_spec);
    io::IoServer server(layout, cfg, vtk, std::move(pictures));
    const auto report = server.run();
    return report.error && !cfg.continue_on_error ? 1 : 0;
  }
  const io::CheckpointHeader* h = header ? &*header : nullptr;
  const io::Checkpoint* whole = ckpt ? &*ckpt : nullptr;
  const basalt::solver::StageProgress* progress = stage_progress ? &*stage_progress : nullptr;
  if (scene.precision == "float" || scene.precision == "mixed")
    return run_compute<float>(cli, scene, layout, cfg, vtk, h, whole, &ckpt_rows, ckpt_file, progress);
  return run_compute<double>(cli, scene, layout, cfg, vtk, h, whole, &ckpt_rows, ckpt_file, progress);
}

}  // namespace

int main(int argc, char** argv) {
  basalt::run::bound_heap_growth();
  basalt::run::prefer_eager_shared_memory_messages();  // before MPI_Init, which reads them
  // A file-size limit (ulimit -f) must make the write fail with EFBIG, named, not kill the rank.
  std::signal(SIGXFSZ, SIG_IGN);
  // FUNNELED: I/O rank 0's picture thread (in-situ pictures) makes no MPI call, only the main thread does.
  int provided = MPI_THREAD_SINGLE;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  // SIGTERM / SIGINT (mpirun forwards them to every rank): the compute ranks stop together at their next
  // agreement point (at most 32 steps on), the output computed so far is written, and the exit status
  // is 128 + the signal's number, after the message.
  install_stop_handlers();
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  int code = 0;
  try {
    code = run_world(argc, argv);
  } catch (const std::exception& e) {
    // Every error reaching here is raised alike on all compute ranks (scene, geometry, agreed run errors).
    if (rank == 0) fmt::print(stderr, "basalt-run: error: {}\n", e.what());
    code = 1;
  }
  if (stop_signal != 0) code = 128 + stop_signal;
  MPI_Finalize();
  return code;
}
