#pragma once
// Parsing of basalt-view's small option values: "1600x1200", "min:max", "x:7.5", "+z".
#include <array>
#include <optional>
#include <string>

namespace basalt::view {

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

/// Each throws std::invalid_argument with a message naming the option and the accepted form.
ImageSize parse_size(const std::string& s);
Range parse_range(const std::string& s);
Cut parse_cut(const std::string& s);
ViewDirection parse_view(const std::string& s);
/// Whole-string number (no trailing characters), else std::invalid_argument naming `what`.
double parse_number(const std::string& s, const std::string& what);

/// Throws std::invalid_argument when `file` cannot be created in its folder (missing or read-only).
void require_writable(const std::string& file);

}  // namespace basalt::view
