#pragma once
// In-situ pictures (basalt-run --render-every N --render SPEC): I/O rank 0 draws a PNG of every N-th
// step from the frames it already receives, on a thread of its own, so that the compute ranks never
// wait for a picture; one that cannot keep up is skipped and counted (docs/io-ranks.md). The drawing
// itself (VTK, OpenGL, a virtual X server) is a module basalt-run loads only when pictures are asked
// for (tools/render/insitu_pictures.cpp); this library sees it as a PictureWriter.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "basalt/io/checkpoint.hpp"
#include "basalt/io/render_options.hpp"

namespace basalt::io {

struct FramePiece;

/// The particles of one step, every compute rank's, in the order their pieces arrived.
struct PictureJob {
  std::int64_t step = 0;
  double time = 0;
  Units units;
  std::vector<std::int64_t> id;
  std::vector<Vec3> position, velocity;
  std::vector<double> radius, mass;
  std::vector<std::int32_t> tag;
  std::vector<std::pair<std::string, std::vector<double>>> fields;  ///< the scene's particle fields

  /// Appends a piece's particles (copies: the pieces go on to the checkpoint writer).
  void append(const FramePiece& piece);
  std::size_t size() const { return id.size(); }
};

/// Draws `job` into the PNG `file` (written under a temporary name, then renamed); returns its size in
/// bytes. Called on the picture thread only (it owns the OpenGL context); throws on failure.
using PictureWriter = std::function<std::uint64_t(const PictureJob& job, const std::filesystem::path& file)>;

/// The PNG of a step: <dir>/pictures/step_<step, 6 digits or more>.png.
std::filesystem::path picture_path(const std::filesystem::path& dir, std::int64_t step);

/// The module's entry point (extern "C", looked up by name with dlsym): a new PictureWriter for `spec`,
/// or nullptr with `*error` set. It starts the virtual X server when there is no display.
inline constexpr const char* kPictureModuleEntry = "basalt_make_picture_writer_v1";
using PictureModuleEntry = PictureWriter* (*)(const RenderSpec* spec, std::string* error);

}  // namespace basalt::io
