#pragma once
#include <vtkRenderWindow.h>

#include <filesystem>

namespace basalt::view {

/// Grabs the window's pixels and writes them as PNG, through a temporary name so that a failed
/// write leaves nothing under `file`. Throws std::runtime_error naming the file.
void write_png(vtkRenderWindow& window, const std::filesystem::path& file);

}  // namespace basalt::view
