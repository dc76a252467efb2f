// basalt-run's in-situ pictures (docs/io-ranks.md), a module the I/O rank loads only when pictures are
// asked for (--render-every): it brings VTK's rendering, OpenGL and X with it, which a run without
// pictures neither links nor loads. Draws with basalt-view's painter, one OpenGL set-up for the run.
#include <fmt/format.h>

#include <cstdlib>
#include <exception>
#include <memory>
#include <stdexcept>
#include <system_error>

#include "basalt/io/pictures.hpp"
#include "basalt/io/vtk_polydata.hpp"
#include "color_field.hpp"
#include "display.hpp"
#include "painter.hpp"
#include "png_output.hpp"

namespace {

namespace io = basalt::io;
namespace bv = basalt::view;

struct State {
  io::RenderSpec spec;
  bv::DrawOptions draw;
  std::unique_ptr<bv::Painter> painter;  // created on the picture thread, at its first picture
};

std::uint64_t draw(State& s, const io::PictureJob& job, const std::filesystem::path& file) {
  io::ParticleArrays a;
  a.id = job.id;
  a.position = job.position;
  a.radius = job.radius;
  a.tag = job.tag;
  a.velocity = job.velocity;
  a.mass = job.mass;
  for (const auto& [name, values] : job.fields) a.fields.emplace_back(name, values);
  io::FrameInfo info;
  info.step = job.step;
  info.time = job.time;
  info.has_clock = true;
  info.units = job.units;
  bv::Prepared p;
  try {
    p = bv::prepare(io::to_polydata(a, info), info, "in-situ picture", file, s.draw);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("{} \"{}\": {}", "render", s.spec.text, e.what()));
  }
  const bv::ColourScale scale =
      s.spec.range ? bv::given_scale(*s.spec.range, p.drawn_values) : bv::robust_scale(p.drawn_values);
  if (!s.painter) s.painter = std::make_unique<bv::Painter>(s.spec.size, 1, s.draw);
  s.painter->draw({&p}, scale);
  bv::write_png(s.painter->window(), file);
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(file, ec);
  return ec ? 0 : static_cast<std::uint64_t>(bytes);
}

}  // namespace

extern "C" __attribute__((visibility("default"))) io::PictureWriter* basalt_make_picture_writer_v1(
    const io::RenderSpec* spec, std::string* error) {
  try {
    // Mesa's software rasteriser draws on this thread alone instead of one thread per core: the
    // pictures take one core at most, the compute ranks keep theirs.
    if (std::getenv("LP_NUM_THREADS") == nullptr) ::setenv("LP_NUM_THREADS", "0", 1);
    bv::ensure_display();
    auto state = std::make_shared<State>();
    state->spec = *spec;
    state->draw.color = spec->color.empty() ? "speed" : spec->color;
    state->draw.cut = spec->cut;
    state->draw.view = spec->view;
    return new io::PictureWriter([state](const io::PictureJob& job, const std::filesystem::path& file) {
      return draw(*state, job, file);
    });
  } catch (const std::exception& e) {
    *error = e.what();
    return nullptr;
  }
}
