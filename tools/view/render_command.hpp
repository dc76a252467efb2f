#pragma once
// basalt-view render: spheres at their radii, coloured by a field, written as a PNG.
#include <filesystem>
#include <optional>
#include <string>

#include "options.hpp"

namespace basalt::view {

struct RenderOptions {
  std::filesystem::path input;
  std::filesystem::path output;
  std::string color;  ///< empty: speed when the frame has it, else radius
  ImageSize size;
  ViewDirection view;
  std::optional<Cut> cut;
  std::optional<Range> range;
  std::optional<std::filesystem::path> reference;
  std::string mapper = "imposter";  ///< "imposter" (GPU ray-cast spheres) or "glyph" (triangulated spheres)
  bool cull = true;                 ///< skip particles buried inside the packing (hidden behind others)
  bool quiet = false;
};

/// Throws io::FormatError (bad input file) or std::invalid_argument (bad option, unknown field).
void render(const RenderOptions& o);

}  // namespace basalt::view
