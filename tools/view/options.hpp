#pragma once
// basalt-view's small option values ("1600x1200", "min:max", "x:7.5", "+z"), shared with basalt-run's
// in-situ pictures (basalt/io/render_options.hpp), and a check that an output can be written.
#include <string>

#include "render_types.hpp"

namespace basalt::view {

/// Throws std::invalid_argument when `file` cannot be created in its folder (missing or read-only).
void require_writable(const std::string& file);

}  // namespace basalt::view
