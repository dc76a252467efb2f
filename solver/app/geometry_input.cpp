#include "geometry_input.hpp"

#include <fmt/format.h>

#include <chrono>
#include <optional>

#include "basalt/io/geometry.hpp"
#include "basalt/solver/core/errors.hpp"

namespace basalt::run {

namespace fs = std::filesystem;

fs::path geometry_as_h5(const fs::path& file, const fs::path& output_dir, const solver::Comm& comm,
                        bool quiet) {
  if (io::geometry_format(file) != io::GeometryFormat::geo) return file;  // basalt-run checked it first
  const fs::path h5 = output_dir / (file.stem().string() + ".from-geo.h5");
  std::optional<std::string> error;
  if (comm.rank() == 0) {
    try {
      const auto t0 = std::chrono::steady_clock::now();
      io::Geometry g = io::read_geo(file);
      io::write_h5(g, h5);
      if (!quiet)
        fmt::print(
            "geometry: {} converted to {} ({} particles, {} bonds, {:.2f} s); convert it once with "
            "`basalt-view convert {} -o FILE.h5` and give that file to skip this step\n",
            file.string(), h5.string(), g.size(), g.bonds.size(),
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), file.string());
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  if (auto e = comm.agree_error(error)) throw solver::InputError(*e);
  return h5;
}

std::unique_ptr<io::GeometryFile> open_geometry(const solver::Scene& scene, const fs::path& output_dir,
                                                const solver::Comm& comm, bool quiet, io::RunInfo& info) {
  // Each compute rank reads a slice of the file's rows and the ranks route them to their owners; a
  // .geo is first converted to HDF5 once, by compute rank 0 (docs/formats.md, "Start-up").
  const fs::path file = geometry_as_h5(scene.geometry, output_dir, comm, quiet);
  std::unique_ptr<io::GeometryFile> rows;
  std::optional<std::string> error;
  try {
    rows = std::make_unique<io::GeometryFile>(file);
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (auto e = comm.agree_error(error)) throw solver::InputError(*e);
  const auto& h = rows->header();
  if (comm.rank() == 0 && (h.units.length != scene.units.length || h.units.time != scene.units.time ||
                           h.units.force != scene.units.force))
    fmt::print(stderr, "warning: the geometry declares units {}, {}, {}; the scene {}, {}, {}\n",
               h.units.length, h.units.time, h.units.force, scene.units.length, scene.units.time,
               scene.units.force);
  info.box_min = h.box_min;
  info.box_max = h.box_max;
  info.periodic = h.periodic;
  info.units = h.units;
  return rows;
}

}  // namespace basalt::run
