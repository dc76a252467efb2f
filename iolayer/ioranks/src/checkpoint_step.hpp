#pragma once
// Writing one assembled checkpoint and accounting for it: shared by the I/O ranks and the
// synchronous writer (Q = 0).
#include <cstdint>
#include <vector>

#include "basalt/io/io_ranks.hpp"

namespace basalt::io::detail {

/// Benchmark only: sleeps until `bytes` took `mb_per_s` (0: no throttle) after `elapsed` seconds.
void throttle(double mb_per_s, std::uint64_t bytes, double elapsed);

/// The scene's `[output] compression` (basalt-run's scene parser accepts and checks the key; the I/O
/// layer reads it from the scene text every writer of checkpoints holds). `none` when absent.
Compression compression_of_scene(const std::string& scene_text);

/// Assembles `pieces` and writes DIR/ckpt_<step>.h5 (atomically); adds it to `rep`; returns its bytes.
std::uint64_t write_checkpoint_step(std::vector<FramePiece>& pieces, const RunInfo& info,
                                    const OutputConfig& cfg, OutputKindReport& rep);

}  // namespace basalt::io::detail
