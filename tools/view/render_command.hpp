#pragma once
// basalt-view render and movie: spheres at their radii, coloured by a field, written as PNG pictures
// (one frame, a strip of panels, a series of files) or as an animated PNG.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "options.hpp"
#include "painter.hpp"

namespace basalt::view {

struct RenderOptions {
  /// One file: one picture. Several files and a .png output: one picture with a panel per file, side
  /// by side in the given order. An output folder (an existing one, or a name ending in '/'): one
  /// picture per file, named after it (ckpt_000400.h5 -> ckpt_000400.png).
  std::vector<std::filesystem::path> inputs;
  std::filesystem::path output;
  std::string color;              ///< empty: speed when the frame has it, else radius
  std::optional<ImageSize> size;  ///< default 1600x1200; a strip: 560x600 per panel plus the colour bar
  ViewDirection view;
  std::optional<Cut> cut;
  std::optional<Range> range;  ///< default: 1st-99th percentile of the particles the cut keeps, all inputs
  std::optional<std::filesystem::path> reference;
  std::string mapper = "imposter";    ///< "imposter" (GPU ray-cast spheres) or "glyph" (triangulated spheres)
  bool cull = true;                   ///< skip particles buried inside the packing (hidden behind others)
  Cracks cracks = Cracks::automatic;  ///< broken bonds: drawn by default when a checkpoint has any
  std::optional<double> crack_radius;
  bool quiet = false;
};

/// Throws io::FormatError (bad input file) or std::invalid_argument (bad option, unknown field).
void render(const RenderOptions& o);

struct MovieOptions {
  RenderOptions render;  ///< inputs: checkpoints, or one folder whose ckpt_<step>.h5 are taken in step order
  double fps = 8;
};

/// Renders every input with one OpenGL set-up and one colour range and writes an animated PNG (.png or
/// .apng, played by browsers and image viewers, no extra software). Throws like render().
void movie(const MovieOptions& o);

/// The checkpoints ckpt_<digits>.h5 of `dir` in step order (no .partial files); empty when none.
std::vector<std::filesystem::path> checkpoints_in(const std::filesystem::path& dir);

}  // namespace basalt::view
