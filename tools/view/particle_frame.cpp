#include "particle_frame.hpp"

#include <fmt/format.h>
#include <vtkDoubleArray.h>
#include <vtkPointData.h>

#include <cmath>
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

/// broken / initial bonds per particle from two particle arrays (0 for a particle that had no bond).
std::vector<double> damage_of(const std::vector<double>& initial, const std::vector<double>& broken) {
  std::vector<double> d(initial.size(), 0.0);
  for (std::size_t i = 0; i < d.size() && i < broken.size(); ++i)
    if (initial[i] > 0) d[i] = broken[i] / initial[i];
  return d;
}

/// Adds a "damage" point array to a frame that has bonds_initial and bonds_broken arrays.
void add_damage(vtkPolyData& pd) {
  auto* pdat = pd.GetPointData();
  vtkDataArray* ini = pdat->GetArray("bonds_initial");
  vtkDataArray* brk = pdat->GetArray("bonds_broken");
  if (!ini || !brk || pdat->GetArray("damage")) return;
  std::vector<double> a(static_cast<std::size_t>(ini->GetNumberOfTuples())), b(a.size());
  for (vtkIdType i = 0; i < ini->GetNumberOfTuples(); ++i) {
    a[static_cast<std::size_t>(i)] = ini->GetTuple1(i);
    b[static_cast<std::size_t>(i)] = brk->GetTuple1(i);
  }
  const auto d = damage_of(a, b);
  auto arr = vtkSmartPointer<vtkDoubleArray>::New();
  arr->SetName("damage");
  arr->SetNumberOfTuples(static_cast<vtkIdType>(d.size()));
  for (std::size_t i = 0; i < d.size(); ++i) arr->SetValue(static_cast<vtkIdType>(i), d[i]);
  pdat->AddArray(arr);
}

ParticleSet from_checkpoint(io::Checkpoint c) {
  ParticleSet s;
  s.cracks = crack_points(c, s.cracks_estimated);
  const std::vector<double>* initial = nullptr;
  const std::vector<double>* broken = nullptr;
  for (const auto& [name, values] : c.particle_fields) {
    if (name == "bonds_initial") initial = &values;
    if (name == "bonds_broken") broken = &values;
  }
  if (initial && broken) s.damage = damage_of(*initial, *broken);
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

std::vector<io::Vec3> crack_points(const io::Checkpoint& c, std::size_t& estimated) {
  const auto& g = c.geometry;
  std::vector<io::Vec3> out;
  estimated = 0;
  for (std::size_t k = 0, nb = 0; k < g.bonds.size() && k < c.bond_broken.size(); ++k) {
    if (c.bond_broken[k] == 0) continue;
    const std::size_t row = nb++;
    if (row < c.bond_break_position.size() && std::isfinite(c.bond_break_position[row][0])) {
      out.push_back(c.bond_break_position[row]);
      continue;
    }
    const auto ia = g.index_of(g.bonds[k].a), ib = g.index_of(g.bonds[k].b);
    if (ia < 0 || ib < 0) continue;  // the checkpoint's validation refuses this
    const auto& xa = g.position[static_cast<std::size_t>(ia)];
    const auto& xb = g.position[static_cast<std::size_t>(ib)];
    const double ra = g.radius[static_cast<std::size_t>(ia)], rb = g.radius[static_cast<std::size_t>(ib)];
    const double w = ra + rb > 0 ? ra / (ra + rb) : 0.5;
    out.push_back({xa[0] + w * (xb[0] - xa[0]), xa[1] + w * (xb[1] - xa[1]), xa[2] + w * (xb[2] - xa[2])});
    ++estimated;
  }
  return out;
}

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
    add_damage(*pd);
    return {pd, io::info_of(*pd), "VTK frame", {}, 0};
  }
  const ParticleSet s = read_particles(file, reference);
  auto pd = io::to_polydata(s.arrays(), s.info);
  if (!s.damage.empty()) {
    auto arr = vtkSmartPointer<vtkDoubleArray>::New();
    arr->SetName("damage");
    arr->SetNumberOfTuples(static_cast<vtkIdType>(s.damage.size()));
    for (std::size_t i = 0; i < s.damage.size(); ++i) arr->SetValue(static_cast<vtkIdType>(i), s.damage[i]);
    pd->GetPointData()->AddArray(arr);
  }
  return {pd, s.info, s.kind, s.cracks, s.cracks_estimated};
}

}  // namespace basalt::view
