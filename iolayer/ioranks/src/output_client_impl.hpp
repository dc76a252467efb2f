#pragma once
// What an OutputClient does, in one of two ways: AsyncClient (async_client.cpp, Q >= 1) posts frames
// and field batches to the I/O ranks; SyncWriter (sync_writer.cpp, Q = 0) has the compute ranks
// write themselves, the baseline. OutputClient (output_client.cpp) holds one and does what both share.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "basalt/io/io_ranks.hpp"

namespace basalt::io::detail {

class OutputClientImpl {
 public:
  OutputClientImpl(const RankLayout& l, OutputConfig c, RunInfo i, VtkFrameWriter v,
                   std::optional<std::string>& e);
  virtual ~OutputClientImpl() = default;
  OutputClientImpl(const OutputClientImpl&) = delete;
  OutputClientImpl& operator=(const OutputClientImpl&) = delete;

  /// Collective over the compute ranks: what the run needs before its first step.
  virtual void start() = 0;
  virtual void submit_frame(const FrameSource& source) = 0;
  /// Hands over the field rows collected so far (a full batch, or the last rows at the end).
  virtual void hand_over_field_rows() = 0;
  virtual void poll() {}
  /// Hands over and completes everything still held (finish(), before the report is reduced).
  virtual void drain() = 0;
  /// After the report's reduction: receives what the I/O ranks still owe this rank.
  virtual void settle() {}

  /// Adds one row to field_rows; hands the batch over when it is full.
  void add_field_row(std::int64_t step, double time, std::span<const double> partials,
                     std::span<const char> due);

  RankLayout layout;
  OutputConfig cfg;
  RunInfo info;
  VtkFrameWriter vtk;
  int compute_rank = 0;

  // Per row: [step, time, due_1 .. due_n (1 or 0), v_1 .. v_n]. Summed over the ranks, a due flag
  // counts the ranks (every rank has the same savers due), so a sum > 0 means due.
  std::vector<double> field_rows;
  std::size_t field_rows_count = 0;

  OutputReport local;                 // Q = 0: what this rank wrote; always: its wait time
  std::optional<std::string>& error;  // OutputClient::error_: the first output error this rank saw
};

std::unique_ptr<OutputClientImpl> make_async_client(const RankLayout& layout, OutputConfig config,
                                                    RunInfo info, VtkFrameWriter vtk,
                                                    std::optional<std::string>& error);
std::unique_ptr<OutputClientImpl> make_sync_writer(const RankLayout& layout, OutputConfig config,
                                                   RunInfo info, VtkFrameWriter vtk,
                                                   std::optional<std::string>& error);

}  // namespace basalt::io::detail
