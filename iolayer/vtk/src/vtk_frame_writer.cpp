#include "basalt/io/vtk_frame_writer.hpp"

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

VtkFrameWriter make_vtk_frame_writer(Units units, double resume_after_time) {
  // Outlives one call and is shared by the copies std::function makes of the closure; the arrays are
  // reused from frame to frame.
  struct State {
    std::unique_ptr<PvdSeries> pvd;
    std::vector<ArrayLayout> layout = frame_layout(/*mass=*/true, /*velocity=*/true, /*displacement=*/false);
    std::vector<std::int64_t> id;
    std::vector<Vec3> position, velocity;
    std::vector<double> radius, mass;
    std::vector<std::int32_t> tag;
    std::vector<std::pair<std::string, std::vector<double>>> fields;
  };
  auto state = std::make_shared<State>();
  return
      [state, units, resume_after_time](const std::vector<FramePiece>& pieces, std::int64_t step, double time,
                                        int piece_index, int n_pieces, const fs::path& dir) -> std::uint64_t {
        auto& s = *state;
        s.id.clear();
        s.position.clear();
        s.velocity.clear();
        s.radius.clear();
        s.mass.clear();
        s.tag.clear();
        // The optional particle fields: the same names in every piece of every rank (the solver's list).
        s.fields.clear();
        if (!pieces.empty())
          for (const auto& f : pieces.front().fields) s.fields.emplace_back(f.first, std::vector<double>{});
        for (const auto& p : pieces) {
          for (std::size_t f = 0; f < s.fields.size() && f < p.fields.size(); ++f)
            s.fields[f].second.insert(s.fields[f].second.end(), p.fields[f].second.begin(),
                                      p.fields[f].second.end());
          s.id.insert(s.id.end(), p.id.begin(), p.id.end());
          s.position.insert(s.position.end(), p.position.begin(), p.position.end());
          s.velocity.insert(s.velocity.end(), p.velocity.begin(), p.velocity.end());
          s.radius.insert(s.radius.end(), p.radius.begin(), p.radius.end());
          s.mass.insert(s.mass.end(), p.mass.begin(), p.mass.end());
          s.tag.insert(s.tag.end(), p.tag.begin(), p.tag.end());
        }
        ParticleArrays a;
        a.id = s.id;
        a.position = s.position;
        a.radius = s.radius;
        a.tag = s.tag;
        a.velocity = s.velocity;
        a.mass = s.mass;
        for (const auto& [name, values] : s.fields) a.fields.emplace_back(name, values);
        // Every piece of a frame announces the same arrays, also a piece with no particles.
        s.layout = frame_layout(/*mass=*/true, /*velocity=*/true, /*displacement=*/false);
        for (const auto& f : s.fields) s.layout.push_back({f.first, "Float64", 1});
        FrameInfo info;
        info.step = step;
        info.time = time;
        info.has_clock = true;
        info.units = units;
        std::uint64_t bytes = size_of(write_piece(dir, step, piece_index, n_pieces, a, info, s.layout));
        if (piece_index == 0) {
          const auto pvtp = write_pvtp(dir, step, n_pieces, s.layout);
          if (!s.pvd) {
            const bool resume = resume_after_time >= 0;
            s.pvd = std::make_unique<PvdSeries>(dir / "frames.pvd", resume);
            if (resume) s.pvd->truncate_after(resume_after_time);
          }
          s.pvd->add(time, pvtp);
          bytes += size_of(pvtp) + size_of(s.pvd->path());
        }
        return bytes;
      };
}

}  // namespace basalt::io
