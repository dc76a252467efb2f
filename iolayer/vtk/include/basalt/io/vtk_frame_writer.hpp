#pragma once
// The VTK frame writer the I/O ranks call (basalt::io_ranks' VtkFrameWriter), built on write_piece,
// write_pvtp and PvdSeries. Layout under the run's output folder <dir>:
//   <dir>/frames/frame_<step>/piece_<i>.vtp   one per writer (I/O rank), its compute ranks' particles
//   <dir>/frames/frame_<step>.pvtp            written by the writer of piece 0
//   <dir>/frames.pvd                          the series, rewritten atomically by the writer of piece 0
#include "basalt/io/io_ranks.hpp"

namespace basalt::io {

/// Every piece holds id, radius, tag, mass, velocity and speed. The writer of piece 0 resumes an
/// existing frames.pvd on its first frame, dropping entries at or after that frame's time (a restart
/// rewrites them). Returns the bytes written; throws FormatError naming the file on failure.
VtkFrameWriter make_vtk_frame_writer(Units units);

}  // namespace basalt::io
