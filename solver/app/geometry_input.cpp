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

}  // namespace basalt::run
