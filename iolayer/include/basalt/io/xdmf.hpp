#pragma once
// XDMF descriptions of checkpoints, so that ParaView (and VisIt) open them directly, with no
// conversion: light XML beside the HDF5 file that names its datasets (docs/io-ranks.md).
#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "basalt/io/checkpoint.hpp"

namespace basalt::io {

/// The file beside the checkpoints that holds the vertex indices 0, 1, ..., M - 1 (dataset `/vertices`,
/// int64, M the most particles of any checkpoint described): every grid's Polyvertex topology reads its
/// first N values through a HyperSlab. ParaView's Xdmf3 readers make no cells without an explicit
/// connectivity; one shared, compressed file keeps it off the checkpoints (docs/formats.md).
inline constexpr const char* kXdmfVerticesFile = "xdmf_vertices.h5";

/// Makes `dir/xdmf_vertices.h5` hold at least `n` indices and returns how many it holds. Rewrites it
/// (atomically, exactly `n` indices, compressed, written one slab at a time) only when it is missing,
/// not ours, damaged, or shorter than `n`. Throws FormatError naming the file.
std::size_t ensure_xdmf_vertices(const std::filesystem::path& dir, std::size_t n);

/// Writes `<h5 without .h5>.xmf` beside the checkpoint `h5` (e.g. ckpt_000400.xmf): a temporal
/// collection of one grid (so that every reader sees its time) of N particles, one Polyvertex cell
/// each (connectivity: the first N values of xdmf_vertices.h5, made long enough first), with the position
/// dataset as geometry and velocity, radius, mass, id and tag as point attributes, read from `h5` (relative
/// references, so the folder can be moved). Atomic (temporary name, rename). Throws FormatError.
void write_checkpoint_xdmf(const Checkpoint& c, const std::filesystem::path& h5);

/// Rewrites `dir/ckpt_series.xmf`: a temporal collection of the grids of every `ckpt_<step>.xmf` in
/// `dir` whose checkpoint exists and whose step is at most `up_to_step` (after a restart, the old
/// run's later checkpoints are left out until they are overwritten), in time order. Each grid's topology
/// is made to read xdmf_vertices.h5 as it now is (made long enough for every grid); a `ckpt_<step>.xmf`
/// whose topology differed (written by an older Basalt without connectivity, or before the vertex file
/// grew) is rewritten too. Atomic. Throws FormatError naming the file.
void write_checkpoint_series_xdmf(const std::filesystem::path& dir, std::int64_t up_to_step);

}  // namespace basalt::io
