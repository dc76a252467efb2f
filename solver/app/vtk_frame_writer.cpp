#include "vtk_frame_writer.hpp"

#include <memory>

#include "basalt/io/vtk_frames.hpp"

namespace basalt::run {

namespace {

std::uint64_t size_of(const std::filesystem::path& p) {
  std::error_code ec;
  const auto s = std::filesystem::file_size(p, ec);
  return ec ? 0 : s;
}

/// The arrays every piece of a frame holds (the same on empty pieces).
std::vector<io::ArrayLayout> frame_layout() {
  const std::int64_t id = 0;
  const io::Vec3 v{0, 0, 0};
  const double r = 1;
  const std::int32_t tag = 0;
  io::ParticleArrays a;
  a.id = {&id, 1};
  a.position = {&v, 1};
  a.radius = {&r, 1};
  a.tag = {&tag, 1};
  a.velocity = {&v, 1};
  a.mass = {&r, 1};
  return io::layout_of(a);
}

}  // namespace

io::VtkFrameWriter make_vtk_frame_writer(const io::Units& units, double resume_after_time) {
  struct State {
    std::unique_ptr<io::PvdSeries> pvd;
    std::vector<io::ArrayLayout> layout = frame_layout();
    std::vector<std::int64_t> id;
    std::vector<io::Vec3> position, velocity;
    std::vector<double> radius, mass;
    std::vector<std::int32_t> tag;
  };
  auto state = std::make_shared<State>();
  return [state, units, resume_after_time](const std::vector<io::FramePiece>& pieces, std::int64_t step,
                                           double time, int piece_index, int n_pieces,
                                           const std::filesystem::path& dir) -> std::uint64_t {
    auto& s = *state;
    s.id.clear();
    s.position.clear();
    s.velocity.clear();
    s.radius.clear();
    s.mass.clear();
    s.tag.clear();
    for (const auto& p : pieces) {
      s.id.insert(s.id.end(), p.id.begin(), p.id.end());
      s.position.insert(s.position.end(), p.position.begin(), p.position.end());
      s.velocity.insert(s.velocity.end(), p.velocity.begin(), p.velocity.end());
      s.radius.insert(s.radius.end(), p.radius.begin(), p.radius.end());
      s.mass.insert(s.mass.end(), p.mass.begin(), p.mass.end());
      s.tag.insert(s.tag.end(), p.tag.begin(), p.tag.end());
    }
    io::ParticleArrays a;
    a.id = s.id;
    a.position = s.position;
    a.radius = s.radius;
    a.tag = s.tag;
    a.velocity = s.velocity;
    a.mass = s.mass;
    io::FrameInfo info;
    info.step = step;
    info.time = time;
    info.has_clock = true;
    info.units = units;
    const auto piece = io::write_piece(dir, step, piece_index, n_pieces, a, info, s.layout);
    std::uint64_t bytes = size_of(piece);
    if (piece_index == 0) {
      const auto pvtp = io::write_pvtp(dir, step, n_pieces, s.layout);
      if (!s.pvd) {
        const bool resume = resume_after_time >= 0;
        s.pvd = std::make_unique<io::PvdSeries>(dir / "frames.pvd", resume);
        if (resume) s.pvd->truncate_after(resume_after_time);
      }
      s.pvd->add(time, pvtp);
      bytes += size_of(pvtp) + size_of(s.pvd->path());
    }
    return bytes;
  };
}

}  // namespace basalt::run
