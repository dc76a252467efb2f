#pragma once
// Dedicated I/O ranks. At start the world splits into P compute ranks and Q I/O ranks; compute
// rank c is served by I/O rank c mod Q. At an output step a compute rank hands a FrameSource
// (its owned particles) to OutputClient::submit_frame, which has it write itself straight into
// one of a bounded pool of buffers, posts a non-blocking send and returns; it blocks only
// when every buffer is still in flight (a slow disk then slows the run, measured, but memory
// stays bounded and nothing is lost). Field-saver partial sums travel in batches to I/O rank 0.
// I/O ranks run IoServer::run(): they wait without spinning, assemble the pieces of a step,
// and write checkpoints (HDF5, atomically), VTK pieces and the fields.csv series.
// With Q = 0 the compute ranks write synchronously themselves (the baseline).
#include <mpi.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "basalt/io/frame.hpp"
#include "basalt/io/pictures.hpp"

namespace basalt::io {

namespace detail {
class OutputClientImpl;  // the asynchronous client (Q >= 1) or the synchronous writer (Q = 0)
}

/// Which ranks compute and which write. Only start-up passes MPI_COMM_WORLD here.
struct RankLayout {
  int world_rank = 0;
  int n_compute = 1;
  int n_io = 0;
  bool is_io = false;
  MPI_Comm compute = MPI_COMM_NULL;  ///< the compute ranks (the solver's only communicator)
  MPI_Comm io = MPI_COMM_NULL;       ///< the I/O ranks among themselves
  MPI_Comm bridge = MPI_COMM_NULL;   ///< duplicate of the world: compute <-> I/O traffic
  /// Compute ranks: bridge rank of the serving I/O rank (-1 when Q = 0).
  int my_io_rank = -1;
  /// I/O ranks: bridge ranks of the compute ranks it serves.
  std::vector<int> served;

  int io_bridge_rank(int io_index) const { return n_compute + io_index; }
};

/// Splits `world` into the last `io_ranks` ranks (I/O) and the rest (compute). Throws
/// std::invalid_argument when io_ranks < 0 or leaves fewer compute than I/O ranks.
RankLayout split_ranks(MPI_Comm world, int io_ranks);
void free_layout(RankLayout& layout);

struct OutputConfig {
  std::filesystem::path dir = "out";
  std::int64_t checkpoint_every = 0;  ///< 0 = off
  std::int64_t frames_every = 0;      ///< VTK frames; 0 = off
  std::int64_t fields_every = 0;      ///< field savers; 0 = off
  std::vector<std::string> field_names;
  int max_frames_in_flight = 2;    ///< per compute rank: bounds memory, sets when a slow disk bites
  int field_batch_rows = 256;      ///< field rows a compute rank collects before sending them
  bool continue_on_error = false;  ///< a failed output stops the run unless this is set
  double throttle_mb_per_s = 0;    ///< benchmark only: make storage this slow on purpose (0 = off)
  bool append_fields = false;      ///< restart: continue an existing fields.csv instead of replacing it
  std::int64_t render_every = 0;   ///< in-situ pictures (I/O ranks only, pictures.hpp); 0 = off
};

/// Per output kind: what was written and what it cost.
struct OutputKindReport {
  std::uint64_t files = 0;
  std::uint64_t bytes = 0;
  double write_seconds = 0;  ///< on the writing ranks
};
struct OutputReport {
  OutputKindReport checkpoints, frames, fields;
  double compute_wait_seconds = 0;  ///< max over compute ranks: time blocked on output
  double io_cpu_seconds = 0;        ///< max over I/O ranks: CPU time (user + system) of the I/O process
  double io_wall_seconds = 0;       ///< max over I/O ranks: wall time of IoServer::run
  std::uint64_t frames_sent = 0;
  /// In-situ pictures: files, bytes and drawing seconds (summed) on I/O rank 0; how many steps asked
  /// for one, how many were skipped (a newer frame came while one waited to be drawn) and which.
  OutputKindReport pictures;
  std::uint64_t pictures_due = 0, pictures_skipped = 0;
  double picture_max_seconds = 0;
  std::string pictures_skipped_steps;  ///< "300, 500" (at most 20 listed)
  std::optional<std::string> error;    ///< first output error, if any
};

/// Writes a VTK frame: the pieces this writer holds, as piece `piece_index` of `n_pieces`.
/// Supplied by the VTK layer (basalt::io_vtk) so this library does not link VTK.
using VtkFrameWriter =
    std::function<std::uint64_t(const std::vector<FramePiece>& pieces, std::int64_t step, double time,
                                int piece_index, int n_pieces, const std::filesystem::path& dir)>;

/// Compute side. One per compute rank; every call except submit_* and poll is collective
/// over the compute ranks (and, for finish, the I/O ranks).
class OutputClient {
 public:
  OutputClient(const RankLayout& layout, OutputConfig config, RunInfo info, VtkFrameWriter vtk = {});
  ~OutputClient();
  OutputClient(const OutputClient&) = delete;
  OutputClient& operator=(const OutputClient&) = delete;

  /// FrameKind bits wanted at this step (0 when none).
  std::uint32_t frame_kinds(std::int64_t step) const;
  bool wants_fields(std::int64_t step) const;

  /// Hands over this rank's frame (kinds, step, time in its header): the source writes it once,
  /// into the buffer that is sent. With Q >= 1 returns once it is posted; with Q = 0 it is
  /// collective over the compute ranks and writes before returning.
  void submit_frame(const FrameSource& source);
  /// Same for a piece held as a FramePiece (tests).
  void submit_frame(const FramePiece& piece);
  /// This rank's partial sums for one saved step (one value per field name); due[c] == 0 marks a saver
  /// not due at this step (an empty cell in fields.csv); an empty `due` means every saver is due. The mask
  /// travels beside the values, so a non-finite sum is written as nan or inf, never taken for "not due".
  void submit_fields(std::int64_t step, double time, std::span<const double> partials,
                     std::span<const char> due = {});
  /// Cheap; call once per step: completes finished sends and picks up errors from I/O ranks.
  void poll();
  /// An output error reported by an I/O rank (or the synchronous writer), if any.
  const std::optional<std::string>& error() const { return error_; }

  /// Flushes everything, tells the I/O ranks the run is over, waits for them; collective over
  /// the whole world (compute and I/O ranks; I/O ranks return the same from IoServer::run).
  OutputReport finish();

 private:
  std::unique_ptr<detail::OutputClientImpl> impl_;
  std::optional<std::string> error_;
};

/// In-situ pictures for I/O rank 0 (with OutputConfig::render_every): the writer, or why there is none
/// (the module could not be loaded, no X server): then the run stops with that error at its start.
struct Pictures {
  PictureWriter draw;
  std::string error;
};

/// I/O side: runs until every compute rank has finished; returns the world-wide report.
class IoServer {
 public:
  IoServer(const RankLayout& layout, OutputConfig config, VtkFrameWriter vtk = {}, Pictures pictures = {});
  OutputReport run();

 private:
  RankLayout layout_;
  OutputConfig config_;
  VtkFrameWriter vtk_;
  Pictures pictures_;
};

/// Waits for a request while sleeping between tests (Open MPI busy-polls in MPI_Wait).
void wait_without_spinning(MPI_Request& request, MPI_Status* status = MPI_STATUS_IGNORE);

}  // namespace basalt::io
