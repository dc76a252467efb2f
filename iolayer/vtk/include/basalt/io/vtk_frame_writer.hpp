#pragma once
// The VTK frame writer the I/O layer calls (io::VtkFrameWriter), built on write_piece, write_pvtp and
// PvdSeries: each writer (an I/O rank, or compute rank 0 with --io-ranks 0) writes its pieces as one
// .vtp; writer 0 also writes the frame's .pvtp and adds it to the series, so ParaView opens it with no
// plugin. Layout under the run's output folder <dir>:
//   <dir>/frame_<step>/piece_<i>.vtp   one per writer, its compute ranks' particles
//   <dir>/frame_<step>.pvtp            written by the writer of piece 0
//   <dir>/frames.pvd                   the series, rewritten atomically by the writer of piece 0
#include "basalt/io/io_ranks.hpp"

namespace basalt::io {

/// Every piece holds id, radius, tag, mass, velocity and speed. `resume_after_time` >= 0: continue
/// an existing frames.pvd, dropping entries after that time (a restart from a checkpoint at that
/// time); < 0: start a new series. The writer returns the bytes it wrote; it throws FormatError naming
/// the file on failure.
VtkFrameWriter make_vtk_frame_writer(Units units, double resume_after_time = -1);

}  // namespace basalt::io
