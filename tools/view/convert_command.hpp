#pragma once
// basalt-view convert: checkpoints/geometries to VTK (.vtp for one, .pvd + one .vtp each for many).
#include <filesystem>
#include <optional>
#include <vector>

namespace basalt::view {

struct ConvertOptions {
  std::vector<std::filesystem::path> inputs;
  std::filesystem::path output;  ///< .vtp (one input) or .pvd (any number)
  std::optional<std::filesystem::path> reference;
  bool quiet = false;
};

void convert(const ConvertOptions& o);

}  // namespace basalt::view
