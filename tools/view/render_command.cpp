#include "render_command.hpp"

#include <fmt/format.h>
#include <unistd.h>
#include <vtkRenderWindow.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <stdexcept>
#include <utility>

#include "color_field.hpp"
#include "painter.hpp"
#include "particle_frame.hpp"
#include "png_output.hpp"

namespace basalt::view {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

DrawOptions draw_options(const RenderOptions& o) {
  DrawOptions d;
  d.color = o.color;
  d.cut = o.cut;
  d.view = o.view;
  d.mapper = o.mapper;
  d.cull = o.cull;
  d.cracks = o.cracks;
  d.crack_radius = o.crack_radius;
  return d;
}

/// Reads `input` and prepares it for drawing.
Prepared prepare(const fs::path& input, const RenderOptions& o) {
  const auto t0 = Clock::now();
  Frame frame = read_frame(input, o.reference);
  Prepared p = prepare(frame.polydata, frame.info, frame.kind, input, draw_options(o), frame.cracks);
  if (p.cracks) p.cracks_estimated = frame.cracks_estimated;
  p.read_s = seconds_since(t0);
  return p;
}

void check_options(const RenderOptions& o) {
  if (o.inputs.empty()) throw std::invalid_argument("nothing to render: give at least one file");
  if (o.mapper != "imposter" && o.mapper != "glyph")
    throw std::invalid_argument(fmt::format("--mapper \"{}\": expected imposter or glyph", o.mapper));
  if (o.crack_radius && !(*o.crack_radius > 0 && std::isfinite(*o.crack_radius)))
    throw std::invalid_argument(fmt::format("--crack-radius {}: expected a length > 0", *o.crack_radius));
}

/// "; 1234 broken bonds, 600 drawn" for the summary line (nothing when cracks are not drawn).
std::string crack_text(const std::vector<Prepared>& frames) {
  std::size_t total = 0, shown = 0, estimated = 0;
  bool any = false;
  for (const auto& f : frames) {
    any = any || f.cracks;
    total += f.cracks_total;
    shown += f.cracks_shown;
    estimated += f.cracks_estimated;
  }
  if (!any) return {};
  std::string s = fmt::format("; {} broken bonds, {} drawn", total, shown);
  if (estimated > 0)
    s += fmt::format(" ({} without a recorded break position: at their ends' current contact point)",
                     estimated);
  return s;
}

bool is_folder_output(const fs::path& out) {
  std::error_code ec;
  const std::string s = out.string();
  return fs::is_directory(out, ec) || (!s.empty() && s.back() == '/');
}

/// Prints "[k/n] name" over itself on a terminal; elsewhere (logs) a line at every tenth.
class Progress {
 public:
  Progress(std::size_t n, bool quiet) : n_(n), quiet_(quiet), tty_(::isatty(STDERR_FILENO) == 1) {}
  void step(std::size_t k, const std::string& what) {
    if (quiet_) return;
    if (tty_) {
      fmt::print(stderr, "\r[{}/{}] {}\033[K", k, n_, what);
      if (k == n_) fmt::print(stderr, "\n");
    } else if (k == n_ || (k * 10 / n_) != ((k - 1) * 10 / n_)) {
      fmt::print(stderr, "[{}/{}] {}\n", k, n_, what);
    }
  }

 private:
  std::size_t n_;
  bool quiet_, tty_;
};

/// Renders `inputs` one picture each through one painter with one colour range; `sink` takes each
/// finished picture (the painter's window) and its frame. Two passes when there are many frames:
/// the first reads every frame for the common range, the second draws (frames are not all kept).
template <class Sink>
void render_each(const RenderOptions& o, ImageSize size, Sink&& sink) {
  const std::size_t n = o.inputs.size();
  const bool keep = n <= 4;
  std::vector<Prepared> kept;
  std::vector<double> pooled;
  Progress reading(n, o.quiet || n < 4);
  for (std::size_t i = 0; i < n; ++i) {
    Prepared p = prepare(o.inputs[i], o);
    if (!o.range)
      pooled.insert(pooled.end(), p.drawn_values.begin(), p.drawn_values.end());
    else if (i == 0)
      pooled = p.drawn_values;
    if (keep) kept.push_back(std::move(p));
    reading.step(i + 1, "read " + o.inputs[i].filename().string());
  }
  const ColourScale scale = o.range ? given_scale(*o.range, pooled) : robust_scale(std::move(pooled));
  Painter painter(size, 1, draw_options(o));
  Progress drawing(n, o.quiet || n < 2);
  for (std::size_t i = 0; i < n; ++i) {
    Prepared p = keep ? std::move(kept[i]) : prepare(o.inputs[i], o);
    painter.draw({&p}, scale);
    sink(painter.window(), p, scale);
    drawing.step(i + 1, "drew " + o.inputs[i].filename().string());
  }
}

std::string scale_text(const ColourScale& s) {
  return fmt::format("range {:.6g}..{:.6g} ({}; values from {:.6g} to {:.6g})", s.range.min, s.range.max,
                     s.how, s.min, s.max);
}

}  // namespace

std::vector<fs::path> checkpoints_in(const fs::path& dir) {
  std::vector<std::pair<long long, fs::path>> found;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() < 9 || name.rfind("ckpt_", 0) != 0 || name.substr(name.size() - 3) != ".h5") continue;
    const std::string digits = name.substr(5, name.size() - 8);
    if (digits.empty() ||
        !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
      continue;
    found.emplace_back(std::stoll(digits), e.path());
  }
  std::sort(found.begin(), found.end());
  std::vector<fs::path> out;
  for (auto& f : found) out.push_back(f.second);
  return out;
}

void render(const RenderOptions& o) {
  check_options(o);
  if (is_folder_output(o.output)) {  // a series: one picture per input
    std::error_code ec;
    fs::create_directory(o.output, ec);
    if (!fs::is_directory(o.output, ec))
      throw std::invalid_argument(fmt::format("cannot create the folder {}", o.output.string()));
    require_writable((o.output / "x.png").string());
    std::set<std::string> names;
    for (const auto& in : o.inputs)
      if (!names.insert(in.stem().string()).second)
        throw std::invalid_argument(fmt::format(
            "two inputs named {}: their pictures would overwrite each other", in.stem().string()));
    const auto t0 = Clock::now();
    ColourScale used;
    render_each(o, o.size.value_or(ImageSize{}),
                [&](vtkRenderWindow& w, const Prepared& p, const ColourScale& s) {
                  write_png(w, o.output / (p.input.stem().string() + ".png"));
                  used = s;
                });
    if (!o.quiet)
      fmt::print("wrote {} pictures into {} (coloured by {}, {}; {:.1f} s)\n", o.inputs.size(),
                 o.output.string(), o.color.empty() ? "the default field" : o.color, scale_text(used),
                 seconds_since(t0));
    return;
  }

  require_writable(o.output.string());
  if (o.output.extension() != ".png")
    throw std::invalid_argument(fmt::format(
        "output {}: render writes PNG images (.png), or into a folder (end it with '/')", o.output.string()));
  const int panels = static_cast<int>(o.inputs.size());
  std::vector<Prepared> frames;
  std::vector<double> pooled;
  for (const auto& in : o.inputs) {
    frames.push_back(prepare(in, o));
    pooled.insert(pooled.end(), frames.back().drawn_values.begin(), frames.back().drawn_values.end());
  }
  const ColourScale scale = o.range ? given_scale(*o.range, pooled) : robust_scale(std::move(pooled));
  const ImageSize size = o.size ? *o.size : panels == 1 ? ImageSize{} : ImageSize{panels * 560 + 180, 600};
  Painter painter(size, panels, draw_options(o));
  std::vector<const Prepared*> ptrs;
  double read_s = 0;
  vtkIdType drawn = 0;
  for (const auto& f : frames) {
    ptrs.push_back(&f);
    read_s += f.read_s;
    drawn += f.only_cracks ? 0 : f.shown->GetNumberOfPoints();  // --only-cracks draws no particle
  }
  const auto t1 = Clock::now();
  painter.draw(ptrs, scale);
  write_png(painter.window(), o.output);
  const double draw_s = seconds_since(t1);
  if (o.quiet) return;
  const Prepared& f = frames.front();
  // With --only-cracks no particle is drawn, so no colour map is used: the line says so instead of a range.
  const bool coloured =
      std::any_of(frames.begin(), frames.end(), [](const Prepared& p) { return !p.only_cracks; });
  const std::string colour = coloured ? fmt::format("coloured by {}, {}", f.field, scale_text(scale))
                                      : std::string("particles not drawn (--only-cracks)");
  if (panels == 1)
    fmt::print("wrote {} ({}x{}, {} particles, {} in view, {} drawn, {}{}; read {:.2f} s, draw {:.2f} s)\n",
               o.output.string(), size.width, size.height, f.total, f.in_view, drawn, colour,
               crack_text(frames), read_s, draw_s);
  else
    fmt::print("wrote {} ({}x{}, {} panels, {} drawn, {}{}; read {:.2f} s, draw {:.2f} s)\n",
               o.output.string(), size.width, size.height, panels, drawn, colour, crack_text(frames), read_s,
               draw_s);
}

void movie(const MovieOptions& m) {
  RenderOptions o = m.render;
  if (o.inputs.size() == 1 && fs::is_directory(o.inputs.front())) {
    const fs::path dir = o.inputs.front();
    o.inputs = checkpoints_in(dir);
    if (o.inputs.empty())
      throw std::invalid_argument(
          fmt::format("{}: no checkpoints (ckpt_<step>.h5) in this folder", dir.string()));
  }
  check_options(o);
  const std::string ext = o.output.extension().string();
  if (ext != ".png" && ext != ".apng")
    throw std::invalid_argument(fmt::format(
        "output {}: movie writes an animated PNG (.png or .apng), which browsers and image viewers play",
        o.output.string()));
  if (!(m.fps > 0 && m.fps <= 100))
    throw std::invalid_argument(fmt::format("--fps {}: expected 0 < fps <= 100", m.fps));
  require_writable(o.output.string());
  const auto t0 = Clock::now();
  const ImageSize size = o.size.value_or(ImageSize{800, 600});
  AnimatedPng apng(o.output, static_cast<int>(o.inputs.size()), m.fps);
  ColourScale used;
  render_each(o, size, [&](vtkRenderWindow& w, const Prepared&, const ColourScale& s) {
    apng.add(w);
    used = s;
  });
  apng.finish();
  if (!o.quiet)
    fmt::print("wrote {} ({} frames, {}x{}, {} frames/s, {}; {:.1f} s)\n", o.output.string(), o.inputs.size(),
               size.width, size.height, m.fps, scale_text(used), seconds_since(t0));
}

}  // namespace basalt::view
