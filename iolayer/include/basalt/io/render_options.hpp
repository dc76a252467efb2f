#pragma once
// What a picture of particles is made with: image size, colour range, cut plane, camera side, and the
// in-situ picture spec ("color=velocity_z,cut=y") that basalt-run takes (--render, output.render).
// Plain values and their parsers, no VTK: basalt-view, basalt-run and the scene parser share them;
// the drawing itself is tools/render (docs/basalt-view.md, docs/io-ranks.md).
#include <array>
#include <optional>
#include <string>

namespace basalt::io {

struct ImageSize {
  int width = 1600;
  int height = 1200;
};
struct Range {
  double min = 0;
  double max = 1;
};
struct Cut {
  int axis = 0;                 ///< 0, 1, 2 for x, y, z
  std::optional<double> value;  ///< default: the middle of the particles' bounding box
};
struct ViewDirection {
  std::array<double, 3> toward_camera{1, -1, 1};  ///< from the focal point to the camera
  std::array<double, 3> up{0, 0, 1};
};

/// Each throws std::invalid_argument with a message naming `option` and the accepted form.
ImageSize parse_size(const std::string& s, const std::string& option = "--size");
Range parse_range(const std::string& s, const std::string& option = "--range");
Cut parse_cut(const std::string& s, const std::string& option = "--cut");
ViewDirection parse_view(const std::string& s, const std::string& option = "--view");
/// Whole-string number (no trailing characters), else std::invalid_argument naming `what`.
double parse_number(const std::string& s, const std::string& what);

/// One in-situ picture's settings: basalt-view render's options of the same names.
struct RenderSpec {
  std::string color;  ///< empty: speed
  std::optional<Cut> cut;
  ViewDirection view;
  std::optional<Range> range;  ///< default: 1st-99th percentile of the particles the cut keeps, per picture
  ImageSize size{800, 600};
  std::string text;  ///< the spec as given
};

/// "color=velocity_z,cut=y,view=-y,range=-0.1:0.1,size=800x600": comma-separated KEY=VALUE, keys color,
/// cut, view, range, size (values as basalt-view's --color, --cut ...); an empty text gives the defaults.
/// Throws std::invalid_argument naming `what` (e.g. "--render") and the key that is wrong.
RenderSpec parse_render_spec(const std::string& text, const std::string& what);

}  // namespace basalt::io
