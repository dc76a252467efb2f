#include "particle_frame.hpp"

#include <fmt/format.h>

#include <system_error>

#include "basalt/io/vtk_polydata.hpp"

namespace basalt::view {

namespace fs = std::filesystem;

io::ParticleArrays ParticleSet::arrays() const {
  io::ParticleArrays a = io::arrays_of(geometry, displacement);
  a.velocity = velocity;
  for (const auto& [name, values] : fields) a.fields.emplace_back(name, values);
  return a;
}

namespace {

bool is_hdf5(const fs::path& file) { return file.extension() == ".h5" || file.extension() == ".hdf5"; }

ParticleSet from_geometry(io::Geometry g) {
  ParticleSet s;
  s.info.units = g.units;
  s.geometry = std::move(g);
  s.kind = "geometry";
  return s;
}

ParticleSet from_checkpoint(io::Checkpoint c) {
  ParticleSet s;
  s.info = io::info_of(c);
  s.geometry = std::move(c.geometry);
  s.velocity = std::move(c.velocity);
  s.fields = std::move(c.particle_fields);
  s.kind = "checkpoint";
  return s;
}

ParticleSet read_any(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw io::FormatError(file, "", "no such file");
  if (!is_hdf5(file)) {
    if (file.extension() != ".geo")
      throw io::FormatError(file, "", "unknown file type (expected .h5, .hdf5, .geo, .vtp or .pvtp)");
    return from_geometry(io::read_geometry(file));
  }
  // A checkpoint extends the geometry schema: try it first, then a plain geometry.
  try {
    return from_checkpoint(io::read_checkpoint(file));
  } catch (const io::FormatError& as_checkpoint) {
    try {
      return from_geometry(io::read_geometry(file));
    } catch (const io::FormatError& as_geometry) {
      throw io::FormatError(
          file, "",
          fmt::format("neither a checkpoint nor a geometry:\n  as checkpoint: {}\n  as geometry: {}",
                      as_checkpoint.what(), as_geometry.what()));
    }
  }
}

}  // namespace

ParticleSet read_particles(const fs::path& file, const std::optional<fs::path>& reference) {
  ParticleSet s = read_any(file);
  if (reference) {
    const ParticleSet ref = read_any(*reference);
    s.displacement = io::displacement_from(s.geometry, ref.geometry, *reference);
  }
  return s;
}

Frame read_frame(const fs::path& file, const std::optional<fs::path>& reference) {
  if (file.extension() == ".vtp" || file.extension() == ".pvtp") {
    if (reference)
      throw io::FormatError(file, "", "--reference applies to checkpoints and geometries, not to VTK files");
    auto pd = io::read_polydata(file);
    return {pd, io::info_of(*pd), "VTK frame"};
  }
  const ParticleSet s = read_particles(file, reference);
  return {io::to_polydata(s.arrays(), s.info), s.info, s.kind};
}

}  // namespace basalt::view
