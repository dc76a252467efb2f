// basalt-pack: fill a box, cylinder, sphere or closed triangle mesh with bonded spheres.
//   basalt-pack box --size 15,15,15 --rmin 0.2 --rmax 1.0 --seed 7 -o cube.h5
// docs/packer.md describes every option and statistic.
#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/packer/assembly.hpp"
#include "basalt/packer/error.hpp"
#include "basalt/packer/pack.hpp"
#include "basalt/packer/request.hpp"
#include "basalt/packer/volume.hpp"
#include "basalt/version.hpp"

namespace fs = std::filesystem;
using basalt::packer::PackError;
using basalt::packer::Vec3;

namespace {

const char* const kShapes[] = {"box", "cylinder", "sphere", "mesh"};

/// The shape is the first word that is not an option: CLI11 says only "A subcommand is required" for
/// `basalt-pack torus ...`. Returns an error message, or empty when the shape is known (or asked --help).
std::string check_shape(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help" || arg == "--version") return {};
    if (!arg.empty() && arg[0] == '-') continue;
    for (const char* s : kShapes)
      if (arg == s) return {};
    return fmt::format(
        "unknown shape '{}' (the first word names the shape): basalt-pack fills a box, "
        "cylinder, sphere or mesh, e.g. "
        "basalt-pack box --size 15,15,15 --rmin 0.2 --rmax 1.0 -o cube.h5",
        arg);
  }
  return "no shape given: basalt-pack fills a box, cylinder, sphere or mesh, e.g. "
         "basalt-pack box --size 15,15,15 --rmin 0.2 --rmax 1.0 -o cube.h5";
}

/// Progress on stderr: a bar redrawn in place on a terminal; otherwise (a log file, a batch job) a plain
/// line every 30 s. Nothing for packs shorter than two seconds. Called from one thread at a time.
class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : enabled_(enabled), tty_(isatty(fileno(stderr)) != 0) {}
  void update(double f) {
    if (!enabled_) return;
    const double t = seconds();
    if (t < 2.0 || t - last_ < (tty_ ? 0.2 : 30.0)) return;
    last_ = t;
    shown_ = true;
    const double eta = f > 0.02 ? t * (1 - f) / f : 0;
    if (!tty_) {
      std::fprintf(stderr, "basalt-pack: packing %3.0f%%, %.0f s, ~%.0f s left\n", 100 * f, t, eta);
      std::fflush(stderr);
      return;
    }
    const int width = 40, fill = static_cast<int>(std::lround(f * width));
    std::fprintf(stderr, "\r[%s%s] %3.0f%%  %.0f s, ~%.0f s left ", std::string(fill, '#').c_str(),
                 std::string(width - fill, '.').c_str(), 100 * f, t, eta);
    std::fflush(stderr);
  }
  void finish() {
    if (shown_ && tty_) std::fprintf(stderr, "\n");
  }
  /// A plain line for the slow steps after packing (bonding, writing) of a pack that showed progress.
  void step(const char* what) {
    if (shown_) std::fprintf(stderr, "basalt-pack: %s (%.0f s)\n", what, seconds());
  }
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  bool enabled_, tty_;
  bool shown_ = false;
  double last_ = 0;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "basalt-pack: fills a volume with bonded spheres whose radii follow a power law "
      "(Basalt " +
      std::string(basalt::kVersion) + ")"};
  app.require_subcommand(1);
  if (const std::string why = check_shape(argc, argv); !why.empty()) {
    std::fprintf(stderr, "basalt-pack: error: %s\n", why.c_str());
    return 2;
  }
  app.set_version_flag("--version", std::string(basalt::kVersion));

  // The options land in the request basalt.pack (Python) fills too: its checks and messages are shared.
  basalt::packer::Request req;
  std::string mesh_file, output;
  auto& popt = req.pack;
  auto& aopt = req.assembly;
  bool record_time = false, quiet = false;
  aopt.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));

  auto* box = app.add_subcommand("box", "an axis-aligned box from --origin to --origin + --size");
  box->add_option("--size", req.size, "edge lengths X,Y,Z")->required();
  box->add_option("--origin", req.origin, "lowest corner X,Y,Z")->capture_default_str();
  auto* cyl = app.add_subcommand("cylinder", "a cylinder along z, base centre at --origin");
  cyl->add_option("--radius", req.radius, "cylinder radius")->required();
  cyl->add_option("--height", req.height, "cylinder height")->required();
  cyl->add_option("--origin", req.origin, "centre of the base X,Y,Z")->capture_default_str();
  auto* sph = app.add_subcommand("sphere", "a ball");
  sph->add_option("--radius", req.radius, "ball radius")->required();
  sph->add_option("--centre,--center", req.centre, "centre X,Y,Z")->capture_default_str();
  auto* mesh = app.add_subcommand("mesh", "the inside of a closed triangle mesh (OFF, STL, OBJ, PLY)");
  mesh->add_option("file", mesh_file, "mesh file")->required();

  for (auto* sub : {box, cyl, sph, mesh}) {
    sub->add_option("--rmin", popt.rmin, "smallest radius")->required();
    sub->add_option("--rmax", popt.rmax, "largest radius")->required();
    sub->add_option("-o,--output", output, "output geometry: .h5 (Basalt) or .geo (ESyS-Particle)")
        ->required();
    sub->add_option("--seed", req.seed, "random seed, 0 .. 2^64-1 (same seed, same file)")
        ->capture_default_str();
    sub->add_flag("--allow-large", req.allow_large,
                  "pack even when more than --max-spheres spheres are expected (about 1 KiB of memory each)");
    sub->add_option("--max-spheres", req.max_spheres,
                    "expected sphere count above which basalt-pack refuses without --allow-large")
        ->capture_default_str();
    sub->add_flag("--allow-low-fraction", req.allow_low_fraction,
                  "write the packing with a warning even when its solid fraction is far below the mode's");
    sub->add_option("--exponent", popt.exponent,
                    "follow the power law N(>r) ~ r^-EXPONENT instead of filling as densely as possible");
    sub->add_option("--target-fraction", popt.target_fraction,
                    "with --exponent: solid fraction whose worth of radii is drawn")
        ->capture_default_str();
    sub->add_flag("--fill", popt.fill_after,
                  "with --exponent: afterwards fill the voids left as densely as possible");
    sub->add_option("--bond-tolerance", aopt.bond_tolerance,
                    "bond every pair whose gap |ci-cj|-ri-rj is <= this (length units)")
        ->capture_default_str();
    sub->add_flag("--no-bonds", req.no_bonds, "write no bonds");
    sub->add_flag("--lattice", req.lattice,
                  "a loose granular fill instead: a cubic lattice of spacing 2 rmax, radii uniform in [rmin, "
                  "rmax], each centre jittered by up to rmax - r (no overlaps; solid fraction ~0.3-0.5); "
                  "pack a column in a box this way for a pile with a free surface");
    sub->add_option("--bond-tag", aopt.bond_tag, "tag of the bonds")->capture_default_str();
    sub->add_option("--overlap-tolerance", popt.overlap_tolerance,
                    "largest overlap allowed between spheres and with the boundary")
        ->capture_default_str();
    sub->add_option("--tag-layer", req.tag_layers,
                    "FACE:THICKNESS:TAG: particles within THICKNESS of FACE get TAG (repeatable; faces: "
                    "xmin..zmax for a box, side/bottom/top for a cylinder, surface for any volume)");
    sub->add_option("--seed-fraction", popt.seed_fraction,
                    "solid fraction placed at random before void filling")
        ->capture_default_str();
    sub->add_option("--bins", aopt.histogram_bins, "radius histogram bins")->capture_default_str();
    sub->add_option("--threads", aopt.threads,
                    "threads for packing (boxes at least 20 rmax wide are packed in tiles), bonding and "
                    "statistics; the file does not depend on it")
        ->capture_default_str();
    sub->add_flag("--record-time", record_time,
                  "also store the pack time and date in the file (then the file differs from run to run)");
    sub->add_flag("-q,--quiet", quiet, "print nothing but errors");
  }
  CLI11_PARSE(app, argc, argv);

  try {
    if (*box)
      req.shape = basalt::packer::Shape::box;
    else if (*cyl)
      req.shape = basalt::packer::Shape::cylinder;
    else if (*sph)
      req.shape = basalt::packer::Shape::sphere;
    else
      req.shape = basalt::packer::Shape::mesh;
    req.mesh_file = mesh_file;
    req.output = output;
    auto prepared = basalt::packer::prepare(req);
    const auto& volume = prepared.volume;

    ProgressBar bar(!quiet);
    prepared.pack.progress = [&](double f) { bar.update(f); };
    double pack_seconds = 0;
    auto result = basalt::packer::run(prepared, [&] {
      bar.finish();
      pack_seconds = bar.seconds();
      bar.step("packed; bonding");
    });
    auto& geometry = result.geometry;
    const auto& st = result.stats;
    const double total_seconds = bar.seconds();

    // The command line without the output name (and -q, --threads), so that the same arguments give the same
    // bytes whatever the file is called.
    std::string command = "basalt-pack";
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "-o" || arg == "--output") {
        ++i;
        continue;
      }
      if (arg.rfind("--output=", 0) == 0 || (arg.rfind("-o", 0) == 0 && arg.size() > 2)) continue;
      if (arg == "-q" || arg == "--quiet") continue;  // changes nothing in the file
      if (arg == "--threads") {                       // nor does the thread count
        ++i;
        continue;
      }
      if (arg.rfind("--threads=", 0) == 0) continue;
      command += " " + arg;
    }
    const auto& low = result.low;
    geometry.attributes["creator"] = fmt::format("basalt-pack {}", basalt::kVersion);
    geometry.attributes["command_line"] = command;
    if (record_time) {
      geometry.statistics["pack_seconds"] = {total_seconds};
      std::time_t now = std::time(nullptr);
      char date[64];
      std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
      geometry.attributes["created"] = date;
    }
    bar.step("bonded; writing");
    basalt::io::write_geometry(geometry, output);

    if (!quiet) {
      fmt::print("basalt-pack {}: {}\n", basalt::kVersion, volume->description());
      fmt::print("  particles            {}\n", st.particles);
      if (popt.exponent)
        fmt::print("  radii drawn/placed   {} / {} (power law, exponent {}){}\n", result.requested,
                   result.requested - result.not_placed, *popt.exponent,
                   popt.fill_after ? fmt::format(", then {} filling voids",
                                                 st.particles + result.not_placed - result.requested)
                                   : "");
      fmt::print("  solid fraction       {:.4f}\n", st.solid_fraction);
      fmt::print("  radii                {:.4g} .. {:.4g}\n", st.min_radius, st.max_radius);
      fmt::print("  fitted exponent      {:.3f}   (counts per log-radius bin ~ r^-alpha)\n",
                 st.histogram.exponent);
      fmt::print("  radius histogram     ");
      for (std::size_t k = 0; k < st.histogram.counts.size(); ++k)
        fmt::print("{}[{:.3g},{:.3g}): {:.0f}", k ? ", " : "", st.histogram.edges[k],
                   st.histogram.edges[k + 1], st.histogram.counts[k]);
      fmt::print("\n");
      fmt::print("  bonds                {}{}\n", st.bonds, aopt.bonds ? "" : " (bonds off)");
      fmt::print("  bonds per particle   {:.3f}\n", st.bonds_per_particle);
      fmt::print("  mean coordination    {:.3f}   (neighbours within the bond tolerance)\n",
                 st.mean_coordination);
      fmt::print("  largest overlap      {:.3g} between spheres, {:.3g} with the boundary\n",
                 st.largest_overlap, std::max(0.0, st.largest_boundary_overlap));
      fmt::print("  time                 {:.3f} s ({:.3f} s packing)\n", total_seconds, pack_seconds);
      fmt::print("  written              {}\n", output);
    }
    if (!low.text.empty()) {
      if (low.far_below)
        std::fprintf(stderr, "basalt-pack: warning: %s (written as --allow-low-fraction asks)\n",
                     low.text.c_str());
      else if (!quiet)
        fmt::print("  note: {}\n", low.text);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "basalt-pack: error: %s\n", e.what());
    return 1;
  }
}
