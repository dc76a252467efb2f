#pragma once
// The VTK frame writer the I/O layer calls (io::VtkFrameWriter): each writer (an I/O rank, or compute
// rank 0 with --io-ranks 0) writes its pieces as one .vtp; writer 0 also writes the frame's .pvtp
// and adds it to DIR/frames.pvd (rewritten atomically), so ParaView opens the series with no plugin.
#include <filesystem>

#include "basalt/io/io_ranks.hpp"

namespace basalt::run {

/// `resume_after_time` >= 0: continue an existing frames.pvd, dropping entries after that time
/// (a restart); < 0: start a new series.
io::VtkFrameWriter make_vtk_frame_writer(const io::Units& units, double resume_after_time = -1);

}  // namespace basalt::run
