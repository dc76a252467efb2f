#include "checkpoint_step.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <chrono>
#include <stdexcept>
#include <thread>
#include <utility>

#include "basalt/io/xdmf.hpp"

namespace basalt::io::detail {

namespace {

std::uint64_t file_size_or_zero(const std::filesystem::path& p) {
  std::error_code ec;
  auto s = std::filesystem::file_size(p, ec);
  return ec ? 0 : s;
}

std::filesystem::path checkpoint_path(const std::filesystem::path& dir, std::int64_t step) {
  return dir / fmt::format("ckpt_{:06d}.h5", step);
}

}  // namespace

Compression compression_of_scene(const std::string& scene_text) {
  toml::table scene;
  try {
    scene = toml::parse(scene_text);
  } catch (const toml::parse_error&) {
    return Compression::none;  // not a TOML scene (tests hand over any text): nothing asked for
  }
  const auto name = scene["output"]["compression"].value<std::string>();
  return name ? parse_compression(*name) : Compression::none;
}

void throttle(double mb_per_s, std::uint64_t bytes, double elapsed) {
  if (mb_per_s <= 0) return;
  const double want = static_cast<double>(bytes) / (mb_per_s * 1e6);
  if (want > elapsed) std::this_thread::sleep_for(std::chrono::duration<double>(want - elapsed));
}

std::uint64_t write_checkpoint_step(std::vector<FramePiece>& pieces, const RunInfo& info,
                                    const OutputConfig& cfg, OutputKindReport& rep) {
  const double t0 = MPI_Wtime();
  // Pieces, checkpoint and file image are spent column by column (assemble and write_checkpoint
  // free what they have copied): the peak stays near one copy of the data plus the file's image.
  Checkpoint c = assemble(std::move(pieces), info);
  const auto path = checkpoint_path(cfg.dir, c.step);
  write_checkpoint(std::move(c), path, compression_of_scene(info.scene_text));  // keeps size and clock
  // ParaView opens the checkpoints as they are: ckpt_<step>.xmf beside each, ckpt_series.xmf for all.
  write_checkpoint_xdmf(c, path);
  write_checkpoint_series_xdmf(cfg.dir, c.step);
  const auto bytes = file_size_or_zero(path);
  throttle(cfg.throttle_mb_per_s, bytes, MPI_Wtime() - t0);
  rep.files += 1;
  rep.bytes += bytes;
  rep.write_seconds += MPI_Wtime() - t0;
  return bytes;
}

}  // namespace basalt::io::detail
