// partition_study: the seed paper's Table 2 (weak scaling 1x1x1 .. 10x10x10 subdomains of 15 mm) computed
// without running the ranks, and a tiny MPI ping-pong for this machine's latency and bandwidth.
//   partition_study table --geometry cube1.geo [--max-n 10] [--pack N] [--skin 0.1] [--csv FILE]
//   partition_study grid --geometry cube1.geo --dims 2,1,1 [--skin 0.1]   (CSV per subdomain)
//   mpirun -np 2 partition_study pingpong [--csv FILE]
// `table` prints a markdown table (like the paper's Table 2) and writes one CSV row per n.
#include <fmt/format.h>
#include <mpi.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/packer/assembly.hpp"
#include "basalt/packer/pack.hpp"
#include "basalt/packer/volume.hpp"
#include "partition_study.hpp"

namespace {

using basalt::bench::Cloud;
using basalt::bench::PartitionResult;

struct Summary {
  double min = 0, mean = 0, max = 0;
};

template <class F>
Summary summarize(const PartitionResult& r, F f) {
  Summary s{1e300, 0, -1e300};
  for (const auto& sub : r.sub) {
    const double v = f(sub);
    s.min = std::min(s.min, v);
    s.max = std::max(s.max, v);
    s.mean += v;
  }
  s.mean /= double(r.sub.size());
  return s;
}

/// GenGeo-like packing (basalt-pack --exponent 2.2 --fill: ~9,200 spheres per 15 mm cube, solid fraction
/// 0.67) unless `dense` (basalt-pack's default dense mode: ~5,100 spheres per 15 mm cube).
Cloud packed_cube(int n, double side, std::uint64_t seed, bool dense) {
  const double L = side * n;
  auto volume = basalt::packer::make_box({0, 0, 0}, {L, L, L});
  basalt::packer::PackOptions popt;
  popt.rmin = 0.2;
  popt.rmax = 1.0;
  popt.seed = seed;
  if (!dense) {
    popt.exponent = 2.2;
    popt.fill_after = true;
  }
  const auto packing = basalt::packer::pack(*volume, popt);
  basalt::packer::AssemblyOptions aopt;
  basalt::packer::AssemblyStats st;
  const auto g = basalt::packer::assemble(*volume, packing, popt, aopt, st);
  return basalt::bench::cloud_from_geometry(g);
}

int table(const std::string& geometry, int max_n, int pack_n, double side, double skin, bool contacts,
          std::uint64_t seed, bool dense, const std::string& csv_path) {
  const Cloud base = basalt::bench::load_cloud(geometry);
  std::unique_ptr<std::ofstream> csv;
  if (!csv_path.empty()) {
    csv = std::make_unique<std::ofstream>(csv_path);
    if (!*csv) throw std::runtime_error(fmt::format("cannot write {}", csv_path));
    *csv << "n,subdomains,side_mm,source,particles,bonds,ghost_width_mm,owned_min,owned_mean,owned_max,"
            "ghosts_min,"
            "ghosts_mean,ghosts_max,ghost_fraction_min,ghost_fraction_mean,ghost_fraction_max,crossing_bonds,"
            "crossing_bonds_max,sent_mean,sent_max,bytes_step_mean,bytes_step_max,bytes_step_total,messages_"
            "max,"
            "seconds\n";
  }
  fmt::print(
      "base: {} ({} particles, {} bonds, rmax {:.4g} mm, longest bond {:.4g} mm); ghost update record {} B "
      "(x, y, z as double), ghost build record {} B\n\n",
      geometry, base.size(), base.bond_count(), base.rmax, base.longest_bond,
      basalt::bench::kGhostUpdateBytes, basalt::bench::kGhostBuildBytes);
  fmt::print(
      "| subdomains | cube side (mm) | particles | source | particles per rank (min / mean / max) | ghosts "
      "per "
      "rank (mean / max) | ghost fraction (mean / max) | bonds crossing faces | bytes per step per rank "
      "(mean "
      "/ max) | messages per rank |\n");
  fmt::print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  std::fflush(stdout);
  for (int n = 1; n <= max_n; ++n) {
    const auto t0 = std::chrono::steady_clock::now();
    const bool packed = n <= pack_n;
    const Cloud cloud = packed ? packed_cube(n, side, seed, dense) : basalt::bench::tile_cloud(base, n, side);
    const double width = basalt::bench::ghost_width(cloud.rmax, cloud.longest_bond, contacts, skin);
    const auto r = basalt::bench::partition(cloud, {n, n, n}, width);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const auto owned = summarize(r, [](const auto& s) { return double(s.owned); });
    const auto ghosts = summarize(r, [](const auto& s) { return double(s.ghosts); });
    const auto frac =
        summarize(r, [](const auto& s) { return double(s.ghosts) / std::max<double>(1, s.owned); });
    const auto crossing = summarize(r, [](const auto& s) { return double(s.crossing_bonds); });
    const auto sent = summarize(r, [](const auto& s) { return double(s.sent); });
    constexpr double B = basalt::bench::kGhostUpdateBytes;
    const auto msgs = summarize(r, [](const auto& s) { return double(s.messages); });
    const double total_bytes = sent.mean * double(r.sub.size()) * B;
    const std::string source =
        packed ? fmt::format("basalt-pack {} seed {}", dense ? "dense" : "power law 2.2 + fill", seed)
               : "tiled cube1.geo";
    fmt::print(
        "| {}x{}x{} = {} | {:g} | {} | {} | {:.0f} / {:.0f} / {:.0f} | {:.0f} / {:.0f} | {:.3f} / {:.3f} | "
        "{} | "
        "{:.0f} / {:.0f} | {:.0f} |\n",
        n, n, n, r.sub.size(), side * n, cloud.size(), source, owned.min, owned.mean, owned.max, ghosts.mean,
        ghosts.max, frac.mean, frac.max, r.crossing_bonds, sent.mean * B, sent.max * B, msgs.max);
    std::fflush(stdout);
    if (csv)
      *csv << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.3f}\n",
                          n, r.sub.size(), side * n, packed ? "packed" : "tiled", cloud.size(),
                          cloud.bond_count(), width, owned.min, owned.mean, owned.max, ghosts.min,
                          ghosts.mean, ghosts.max, frac.min, frac.mean, frac.max, r.crossing_bonds,
                          crossing.max, sent.mean, sent.max, sent.mean * B, sent.max * B, total_bytes,
                          msgs.max, secs);
  }
  return 0;
}

int grid(const std::string& geometry, const std::array<int, 3>& dims, double skin, bool contacts) {
  const Cloud cloud = basalt::bench::load_cloud(geometry);
  const double width = basalt::bench::ghost_width(cloud.rmax, cloud.longest_bond, contacts, skin);
  const auto r = basalt::bench::partition(cloud, dims, width);
  fmt::print("rank,cx,cy,cz,owned,ghosts,sent,crossing_bonds,messages,bytes_step\n");
  for (std::size_t k = 0; k < r.sub.size(); ++k) {
    const auto& s = r.sub[k];
    fmt::print("{},{},{},{},{},{},{},{},{},{}\n", k, s.coords[0], s.coords[1], s.coords[2], s.owned, s.ghosts,
               s.sent, s.crossing_bonds, s.messages, s.sent * basalt::bench::kGhostUpdateBytes);
  }
  return 0;
}

/// Round trip of `bytes` between ranks 0 and 1, `reps` times after a warm-up; one-way time (half the
/// round trip): {median, best} of `trials` trials.
std::pair<double, double> pingpong_once(std::size_t bytes, int reps, int trials, int rank) {
  std::vector<char> buf(std::max<std::size_t>(bytes, 1));
  std::vector<double> t;
  for (int trial = 0; trial <= trials; ++trial) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = MPI_Wtime();
    for (int k = 0; k < reps; ++k) {
      if (rank == 0) {
        MPI_Send(buf.data(), int(bytes), MPI_BYTE, 1, 0, MPI_COMM_WORLD);
        MPI_Recv(buf.data(), int(bytes), MPI_BYTE, 1, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      } else if (rank == 1) {
        MPI_Recv(buf.data(), int(bytes), MPI_BYTE, 0, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        MPI_Send(buf.data(), int(bytes), MPI_BYTE, 0, 0, MPI_COMM_WORLD);
      }
    }
    if (trial > 0) t.push_back((MPI_Wtime() - t0) / reps / 2);  // trial 0 warms up
  }
  std::sort(t.begin(), t.end());
  return {t[t.size() / 2], t.front()};
}

int pingpong(const std::string& csv_path) {
  int rank = 0, size = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size < 2) {
    if (rank == 0) fmt::print(stderr, "partition_study pingpong: run with at least 2 ranks (mpirun -np 2)\n");
    return 2;
  }
  struct Row {
    std::size_t bytes;
    double median, best;
  };
  std::vector<Row> rows;
  for (std::size_t bytes : {std::size_t(8), std::size_t(1024), std::size_t(16384), std::size_t(131072),
                            std::size_t(1048576), std::size_t(4194304)}) {
    const int reps = bytes <= 16384 ? 2000 : (bytes <= 131072 ? 300 : 40);
    const auto [med, best] = pingpong_once(bytes, reps, 9, rank);
    rows.push_back({bytes, med, best});
  }
  // Allreduce of one double (the solver's per-step max of displacements).
  std::vector<double> ta;
  for (int trial = 0; trial < 9; ++trial) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = MPI_Wtime();
    double v = rank, out = 0;
    for (int k = 0; k < 2000; ++k) MPI_Allreduce(&v, &out, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    ta.push_back((MPI_Wtime() - t0) / 2000);
  }
  std::sort(ta.begin(), ta.end());
  if (rank == 0) {
    // On a shared machine a trial can wait for the other rank to be scheduled, so the estimates use the
    // best trial: latency = the best time of a message of <= 1 KB; bandwidth = the slope between the two
    // largest sizes (free of any constant offset). The medians are in the CSV as measured.
    double lat = 1e300, lat_best = 1e300;
    for (const auto& r : rows)
      if (r.bytes <= 1024) {
        lat = std::min(lat, r.median);
        lat_best = std::min(lat_best, r.best);
      }
    const auto& r1 = rows[rows.size() - 2];
    const auto& r2 = rows.back();
    const double bw = double(r2.bytes - r1.bytes) / (r2.median - r1.median);
    const double bw_best = double(r2.bytes - r1.bytes) / (r2.best - r1.best);
    fmt::print("ping-pong between 2 ranks, one-way time (median and best of 9 trials):\n");
    for (const auto& r : rows)
      fmt::print("  {:>8} B  {:9.2f} us ({:8.1f} MB/s)  best {:9.2f} us ({:8.1f} MB/s)\n", r.bytes,
                 r.median * 1e6, double(r.bytes) / r.median / 1e6, r.best * 1e6,
                 double(r.bytes) / r.best / 1e6);
    fmt::print(
        "latency {:.2f} us (best {:.2f}), bandwidth {:.0f} MB/s (best {:.0f}); allreduce(1 double) on {} "
        "ranks "
        "{:.2f} us (best {:.2f})\n",
        lat * 1e6, lat_best * 1e6, bw / 1e6, bw_best / 1e6, size, ta[ta.size() / 2] * 1e6, ta.front() * 1e6);
    if (!csv_path.empty()) {
      std::ofstream f(csv_path);
      if (!f) throw std::runtime_error(fmt::format("cannot write {}", csv_path));
      f << "bytes,seconds_one_way_median,seconds_one_way_best\n";
      for (const auto& r : rows) f << fmt::format("{},{:.9g},{:.9g}\n", r.bytes, r.median, r.best);
      f << fmt::format(
          "# latency_s={:.9g} bandwidth_Bps={:.9g} allreduce_s={:.9g} latency_best_s={:.9g} "
          "bandwidth_best_Bps={:.9g} allreduce_best_s={:.9g} ranks={}\n",
          lat, bw, ta[ta.size() / 2], lat_best, bw_best, ta.front(), size);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  CLI::App app{"partition_study: the seed paper's Table 2 without running the ranks; MPI ping-pong"};
  app.require_subcommand(1);
  std::string geometry, csv;
  int max_n = 10, pack_n = 0;
  double side = 15.0, skin = 0.1;
  bool no_contacts = false;
  std::uint64_t seed = 7;
  auto* tab = app.add_subcommand("table", "per n = 1..max-n: n^3 subdomains of a cube of side n x side");
  tab->add_option("--geometry", geometry, "the base cube (.geo or .h5), tiled n x n x n")->required();
  tab->add_option("--max-n", max_n, "largest n")->capture_default_str()->check(CLI::Range(1, 12));
  tab->add_option("--pack", pack_n, "pack cubes with n <= this with basalt::packer instead of tiling")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  tab->add_option("--side", side, "subdomain side (mm): the tile shift")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  tab->add_option("--skin", skin, "the scene's run.skin (mm)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  tab->add_flag("--no-contacts", no_contacts,
                "the scene has no contact interaction (ghost width from bonds only)");
  tab->add_option("--seed", seed, "packer seed for --pack")->capture_default_str();
  bool dense = false;
  tab->add_flag("--dense", dense, "with --pack: basalt-pack's dense mode instead of --exponent 2.2 --fill");
  tab->add_option("--csv", csv, "write one row per n here");
  std::vector<int> dims;
  auto* grd = app.add_subcommand("grid", "one geometry on one rank grid: CSV per subdomain");
  grd->add_option("--geometry", geometry, "geometry (.geo or .h5)")->required();
  grd->add_option("--dims", dims, "grid X,Y,Z")
      ->required()
      ->expected(3)
      ->delimiter(',')
      ->check(CLI::Range(1, 64));
  grd->add_option("--skin", skin, "the scene's run.skin (mm)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  grd->add_flag("--no-contacts", no_contacts, "the scene has no contact interaction");
  auto* pp = app.add_subcommand("pingpong", "latency, bandwidth and allreduce time between ranks 0 and 1");
  pp->add_option("--csv", csv, "write the measurements here");
  int rc = 0;
  try {
    app.parse(argc, argv);
    if (*tab)
      rc = rank == 0 ? table(geometry, max_n, pack_n, side, skin, !no_contacts, seed, dense, csv) : 0;
    else if (*grd)
      rc = rank == 0 ? grid(geometry, {dims[0], dims[1], dims[2]}, skin, !no_contacts) : 0;
    else
      rc = pingpong(csv);
  } catch (const CLI::ParseError& e) {
    rc = rank == 0 ? app.exit(e) : 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "partition_study: error: {}\n", e.what());
    rc = 1;
  }
  MPI_Finalize();
  return rc;
}
