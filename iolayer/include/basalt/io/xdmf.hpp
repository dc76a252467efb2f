#pragma once
// XDMF descriptions of checkpoints, so that ParaView (and VisIt) open them directly, with no
// conversion: light XML beside the HDF5 file that names its datasets (docs/io-ranks.md).
#include <filesystem>

#include "basalt/io/checkpoint.hpp"

namespace basalt::io {

/// Writes `<h5 without .h5>.xmf` beside the checkpoint `h5` (e.g. ckpt_000400.xmf): one grid of N
/// particles (one Polyvertex cell each) at the checkpoint's time, with the position dataset as
/// geometry and velocity, radius, mass, id and tag as point attributes, read from `h5` (a relative
/// reference, so the folder can be moved). Atomic (temporary name, rename). Throws FormatError.
void write_checkpoint_xdmf(const Checkpoint& c, const std::filesystem::path& h5);

/// Rewrites `dir/ckpt_series.xmf`: a temporal collection of the grids of every `ckpt_<step>.xmf` in
/// `dir` whose checkpoint exists and whose step is at most `up_to_step` (after a restart, the old
/// run's later checkpoints are left out until they are overwritten), in time order. Atomic. Throws
/// FormatError naming the file.
void write_checkpoint_series_xdmf(const std::filesystem::path& dir, std::int64_t up_to_step);

}  // namespace basalt::io
