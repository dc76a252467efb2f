#pragma once
// basalt-run's in-situ pictures come from a module (basalt-render-insitu.so, tools/render) that I/O rank 0
// loads only when pictures are asked for: a run without them neither links nor loads VTK's rendering.
#include "basalt/io/io_ranks.hpp"

namespace basalt::run {

/// Loads the module from basalt-run's folder (or $BASALT_RENDER_MODULE) and makes the picture writer for
/// `spec` (which starts a virtual X server when there is no display). Never throws: a failure is
/// returned in Pictures::error, naming the module.
io::Pictures load_picture_module(const io::RenderSpec& spec);

}  // namespace basalt::run
