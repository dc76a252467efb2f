#pragma once
// The picture settings' value types (basalt/io/render_options.hpp) under basalt-view's namespace.
#include "basalt/io/render_options.hpp"

namespace basalt::view {

using io::Cut;
using io::ImageSize;
using io::parse_cut;
using io::parse_number;
using io::parse_range;
using io::parse_size;
using io::parse_view;
using io::Range;
using io::ViewDirection;

}  // namespace basalt::view
