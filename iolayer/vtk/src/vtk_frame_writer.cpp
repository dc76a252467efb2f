#include "basalt/io/vtk_frame_writer.hpp"

#include <fmt/format.h>

#include <memory>
#include <system_error>

#include "basalt/io/vtk_frames.hpp"

namespace basalt::io {

namespace fs = std::filesystem;

namespace {

std::uint64_t size_of(const fs::path& file) {
  std::error_code ec;
  const auto s = fs::file_size(file, ec);
  return ec ? 0 : static_cast<std::uint64_t>(s);
}

}  // namespace

VtkFrameWriter make_vtk_frame_writer(Units units) {
  // The series outlives one call: shared by the copies std::function makes of this closure.
  auto series = std::make_shared<std::unique_ptr<PvdSeries>>();
  return [units, series](const std::vector<FramePiece>& pieces, std::int64_t step, double time,
                         int piece_index, int n_pieces, const fs::path& dir) -> std::uint64_t {
    std::size_t n = 0;
    for (const auto& p : pieces) n += p.size();
    std::vector<std::int64_t> id;
    std::vector<Vec3> position, velocity;
    std::vector<double> radius, mass;
    std::vector<std::int32_t> tag;
    id.reserve(n);
    position.reserve(n);
    velocity.reserve(n);
    radius.reserve(n);
    mass.reserve(n);
    tag.reserve(n);
    for (const auto& p : pieces) {
      if (p.position.size() != p.size() || p.velocity.size() != p.size() || p.radius.size() != p.size() ||
          p.mass.size() != p.size() || p.tag.size() != p.size())
        throw std::invalid_argument(fmt::format(
            "frame piece of compute rank {} at step {}: array lengths differ", p.source_rank, step));
      id.insert(id.end(), p.id.begin(), p.id.end());
      position.insert(position.end(), p.position.begin(), p.position.end());
      velocity.insert(velocity.end(), p.velocity.begin(), p.velocity.end());
      radius.insert(radius.end(), p.radius.begin(), p.radius.end());
      mass.insert(mass.end(), p.mass.begin(), p.mass.end());
      tag.insert(tag.end(), p.tag.begin(), p.tag.end());
    }
    ParticleArrays a;
    a.id = id;
    a.position = position;
    a.velocity = velocity;
    a.radius = radius;
    a.mass = mass;
    a.tag = tag;
    FrameInfo info;
    info.step = step;
    info.time = time;
    info.has_clock = true;
    info.units = units;
    const auto layout = frame_layout(true, true, false);
    const fs::path frames = dir / "frames";
    std::uint64_t bytes = size_of(write_piece(frames, step, piece_index, n_pieces, a, info, layout));
    if (piece_index == 0) {
      const fs::path pvtp = write_pvtp(frames, step, n_pieces, layout);
      if (!*series) {
        *series = std::make_unique<PvdSeries>(dir / "frames.pvd", true);
        (*series)->truncate_before_or_at(time);
      }
      (*series)->add(time, pvtp);
      bytes += size_of(pvtp) + size_of((*series)->path());
    }
    return bytes;
  };
}

}  // namespace basalt::io
