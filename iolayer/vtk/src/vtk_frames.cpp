#include "basalt/io/vtk_frames.hpp"

#include <fmt/format.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>
#include <system_error>

#include "basalt/io/vtk_polydata.hpp"
#include "text_file.hpp"
#include "vtk_errors.hpp"

namespace basalt::io {

namespace fs = std::filesystem;

void ParticleArrays::check() const {
  const std::size_t n = id.size();
  auto bad = [n](std::size_t m, bool optional) { return optional ? (m != 0 && m != n) : m != n; };
  if (bad(position.size(), false) || bad(radius.size(), false) || bad(tag.size(), false) ||
      bad(velocity.size(), true) || bad(mass.size(), true) || bad(displacement.size(), true) ||
      std::any_of(fields.begin(), fields.end(), [&](const auto& f) { return f.second.size() != n; }))
    throw std::invalid_argument(fmt::format(
        "particle arrays differ in length: id {}, position {}, radius {}, tag {}, velocity {}, mass {}, "
        "displacement {}",
        n, position.size(), radius.size(), tag.size(), velocity.size(), mass.size(), displacement.size()));
}

ParticleArrays arrays_of(const Geometry& g, std::span<const Vec3> displacement) {
  ParticleArrays a;
  a.id = g.id;
  a.position = g.position;
  a.radius = g.radius;
  a.tag = g.tag;
  a.mass = g.mass;
  a.displacement = displacement;
  return a;
}

ParticleArrays arrays_of(const Checkpoint& c, std::span<const Vec3> displacement) {
  ParticleArrays a = arrays_of(c.geometry, displacement);
  a.velocity = c.velocity;
  for (const auto& [name, values] : c.particle_fields) a.fields.emplace_back(name, values);
  return a;
}

FrameInfo info_of(const Checkpoint& c) {
  FrameInfo info;
  info.step = c.step;
  info.time = c.time;
  info.has_clock = true;
  info.units = c.geometry.units;
  return info;
}

std::vector<Vec3> displacement_from(const Geometry& current, const Geometry& reference,
                                    const fs::path& reference_file) {
  std::vector<Vec3> d(current.size());
  for (std::size_t i = 0; i < current.size(); ++i) {
    const std::int64_t j = reference.index_of(current.id[i]);
    if (j < 0)
      throw FormatError(reference_file, "particles",
                        fmt::format("particle id {} is not in the reference geometry", current.id[i]));
    const Vec3& p = current.position[i];
    const Vec3& q = reference.position[static_cast<std::size_t>(j)];
    d[i] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
  }
  return d;
}

std::vector<ArrayLayout> frame_layout(bool mass, bool velocity, bool displacement) {
  std::vector<ArrayLayout> l{{"id", "Int64", 1}, {"radius", "Float64", 1}, {"tag", "Int32", 1}};
  if (mass) l.push_back({"mass", "Float64", 1});
  if (velocity) {
    l.push_back({"velocity", "Float64", 3});
    l.push_back({"speed", "Float64", 1});
  }
  if (displacement) l.push_back({"displacement", "Float64", 3});
  return l;
}

std::vector<ArrayLayout> layout_of(const ParticleArrays& a) {
  auto l = frame_layout(!a.mass.empty(), !a.velocity.empty(), !a.displacement.empty());
  for (const auto& f : a.fields) l.push_back({f.first, "Float64", 1});
  return l;
}

void write_vtp(const ParticleArrays& a, const FrameInfo& info, const fs::path& file,
               const std::vector<ArrayLayout>* layout) {
  detail::require_folder(file);
  auto pd = to_polydata(a, info, layout);
  const fs::path tmp = detail::partial_name(file);
  auto catcher = vtkSmartPointer<detail::VtkErrorCatcher>::New();
  auto writer = vtkSmartPointer<vtkXMLPolyDataWriter>::New();
  catcher->watch(writer);
  writer->SetInputData(pd);
  writer->SetFileName(tmp.c_str());
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();  // raw binary
  writer->SetHeaderTypeToUInt64();
  writer->SetCompressorTypeToLZ4();
  const int ok = writer->Write();
  if (ok != 1 || catcher->count > 0) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw FormatError(
        file, "", "VTK cannot write it: " + (catcher->message.empty() ? "write failed" : catcher->message));
  }
  detail::commit(tmp, file);
}

void write_vtp(const Checkpoint& c, const fs::path& file, std::span<const Vec3> displacement) {
  write_vtp(arrays_of(c, displacement), info_of(c), file);
}

namespace {
std::string frame_name(std::int64_t step) { return fmt::format("frame_{:08d}", step); }
std::string piece_name(int piece) { return fmt::format("piece_{:04d}.vtp", piece); }
}  // namespace

fs::path piece_path(const fs::path& frame_dir, std::int64_t step, int piece) {
  return frame_dir / frame_name(step) / piece_name(piece);
}

fs::path pvtp_path(const fs::path& frame_dir, std::int64_t step) {
  return frame_dir / (frame_name(step) + ".pvtp");
}

fs::path write_piece(const fs::path& frame_dir, std::int64_t step, int piece, int n_pieces,
                     const ParticleArrays& a, const FrameInfo& info, const std::vector<ArrayLayout>& layout) {
  if (n_pieces < 1 || piece < 0 || piece >= n_pieces)
    throw std::invalid_argument(fmt::format("piece {} of {} pieces", piece, n_pieces));
  const fs::path file = piece_path(frame_dir, step, piece);
  std::error_code ec;
  fs::create_directories(file.parent_path(), ec);  // several ranks may race here: existing is fine
  if (!fs::is_directory(file.parent_path()))
    throw FormatError(file, "",
                      fmt::format("cannot create folder {}: {}", file.parent_path().string(), ec.message()));
  write_vtp(a, info, file, &layout);
  return file;
}

fs::path write_pvtp(const fs::path& frame_dir, std::int64_t step, int n_pieces,
                    const std::vector<ArrayLayout>& layout) {
  if (n_pieces < 1) throw std::invalid_argument(fmt::format("{} pieces", n_pieces));
  const fs::path file = pvtp_path(frame_dir, step);
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"PPolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      "  <PPolyData GhostLevel=\"0\">\n"
      "    <PPointData Scalars=\"radius\">\n";
  for (const auto& arr : layout)
    xml += fmt::format("      <PDataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\"/>\n", arr.type,
                       detail::xml_escape(arr.name), arr.components);
  xml +=
      "    </PPointData>\n"
      "    <PPoints>\n"
      "      <PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n"
      "    </PPoints>\n";
  for (int p = 0; p < n_pieces; ++p)
    xml += fmt::format("    <Piece Source=\"{}/{}\"/>\n", frame_name(step), piece_name(p));
  xml += "  </PPolyData>\n</VTKFile>\n";
  detail::write_text_atomically(file, xml);
  return file;
}

}  // namespace basalt::io
