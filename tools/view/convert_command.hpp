#pragma once
// basalt-view convert: checkpoints/geometries to VTK (.vtp for one, .pvd + one .vtp each for many), or a
// geometry to another geometry format (.geo <-> .h5).
#include <filesystem>
#include <optional>
#include <vector>

namespace basalt::view {

struct ConvertOptions {
  std::vector<std::filesystem::path> inputs;
  std::filesystem::path output;  ///< .vtp (one input), .pvd (any number), .h5/.geo (one geometry)
  std::optional<std::filesystem::path> reference;
  bool quiet = false;
};

void convert(const ConvertOptions& o);

}  // namespace basalt::view
