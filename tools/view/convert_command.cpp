#include "convert_command.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <system_error>

#include "basalt/io/geometry.hpp"
#include "basalt/io/vtk_frames.hpp"
#include "options.hpp"
#include "particle_frame.hpp"

namespace basalt::view {

namespace fs = std::filesystem;

void convert(const ConvertOptions& o) {
  if (o.inputs.empty()) throw std::invalid_argument("convert: no input files");
  require_writable(o.output.string());
  // Check every input before writing anything, so that a typo in the 100th name costs no work.
  for (const auto& in : o.inputs) {
    std::error_code ec;
    if (!fs::is_regular_file(in, ec)) throw io::FormatError(in, "", "no such file");
  }
  for (const auto& in : o.inputs)
    if (in.extension() == ".vtp" || in.extension() == ".pvtp")
      throw std::invalid_argument(
          fmt::format("{}: already a VTK file; convert reads checkpoints and geometries", in.string()));
  // Geometry to geometry: a .geo (ESyS-Particle) to .h5, which basalt-run's ranks read in slices, or back.
  const auto geometry_ext = [](const fs::path& p) {
    std::string e = p.extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
    return e == ".h5" || e == ".hdf5" || e == ".geo";
  };
  if (geometry_ext(o.output)) {
    if (o.inputs.size() != 1)
      throw std::invalid_argument(
          fmt::format("{} inputs: a geometry output takes one geometry input", o.inputs.size()));
    const io::Geometry g = io::read_geometry(o.inputs[0]);
    io::write_geometry(g, o.output);
    if (!o.quiet)
      fmt::print("wrote {} ({} particles, {} bonds)\n", o.output.string(), g.size(), g.bonds.size());
    return;
  }
  if (o.output.extension() == ".vtp") {
    if (o.inputs.size() != 1)
      throw std::invalid_argument(
          fmt::format("{} inputs: a series needs a .pvd output (one .vtp per input is written beside it)",
                      o.inputs.size()));
    const ParticleSet s = read_particles(o.inputs[0], o.reference);
    io::write_vtp(s.arrays(), s.info, o.output);
    if (!o.quiet) fmt::print("wrote {} ({} particles, {})\n", o.output.string(), s.geometry.size(), s.kind);
    return;
  }
  if (o.output.extension() != ".pvd")
    throw std::invalid_argument(
        fmt::format("output {}: expected .vtp (one input) or .pvd (a series)", o.output.string()));

  // A series: <name>.pvd plus the folder <name>/ with one .vtp per input, listed in time order.
  const fs::path folder = o.output.parent_path() / o.output.stem();
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (!fs::is_directory(folder))
    throw std::invalid_argument(fmt::format("cannot create folder {}: {}", folder.string(), ec.message()));
  struct Written {
    double time;
    fs::path file;
  };
  std::vector<Written> written;
  for (std::size_t k = 0; k < o.inputs.size(); ++k) {
    const fs::path& in = o.inputs[k];
    const ParticleSet s = read_particles(in, o.reference);
    const fs::path out = folder / (in.stem().string() + ".vtp");
    if (std::any_of(written.begin(), written.end(), [&](const Written& w) { return w.file == out; }))
      throw std::invalid_argument(
          fmt::format("two inputs named {}: their frames would overwrite each other", in.stem().string()));
    io::write_vtp(s.arrays(), s.info, out);
    // A geometry has no clock: number such frames by their position in the list.
    written.push_back({s.info.has_clock ? s.info.time : static_cast<double>(k), out});
    if (!o.quiet) fmt::print("wrote {} ({} particles, {})\n", out.string(), s.geometry.size(), s.kind);
  }
  std::stable_sort(written.begin(), written.end(),
                   [](const Written& a, const Written& b) { return a.time < b.time; });
  io::PvdSeries series(o.output);
  for (const auto& w : written) series.add(w.time, fs::path(o.output.stem()) / w.file.filename());
  if (!o.quiet) fmt::print("wrote {} ({} frames)\n", o.output.string(), written.size());
}

}  // namespace basalt::view
