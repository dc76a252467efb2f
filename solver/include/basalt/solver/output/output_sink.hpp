#pragma once
// Where a run's output goes, seen from the solver. Called on EVERY compute rank with this rank's
// local data: partial sums of the field savers (no reduction in the solver) and its share of a
// frame (owned particles, its bonds) as a source that writes itself. The implementation decides where it
// goes: basalt-run's adapter hands it to basalt::io::OutputClient (dedicated I/O ranks, or synchronous
// writing from the compute ranks with --io-ranks 0). The solver library stays free of the I/O service.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "basalt/io/frame_writer.hpp"

namespace basalt::solver {

class OutputSink {
 public:
  virtual ~OutputSink() = default;
  /// Field-saver column names (after "step" and "time"); called once before the first step.
  virtual void begin(const std::vector<std::string>& columns) = 0;
  /// This rank's partial sums at a step where at least one saver is due; due[c] == 0: column c's saver
  /// is not due (its value is meaningless). A non-finite value is a real one (written as nan or inf).
  virtual void fields(std::int64_t step, double time, std::span<const double> local_partials,
                      std::span<const char> due) = 0;
  /// io::FrameKind bits wanted at this step (0: none). Must be the same on every compute rank.
  virtual std::uint32_t frame_kinds(std::int64_t step) const = 0;
  /// This rank's share of the frame of its step (kinds set in its header): the sink has it write
  /// itself into whatever it sends or stores (io::FrameWriter).
  virtual void frame(const io::FrameSource& source) = 0;
  /// Cheap, once per step: an output error seen by this rank, if any (not collective).
  virtual std::optional<std::string> poll() = 0;
  /// Whether the run goes on without the failed output (scene: [output] on_error = "continue").
  virtual bool continue_on_error() const = 0;
  /// End of the run (collective over the compute ranks).
  virtual void flush() = 0;
  /// Collective, before the run stops on an error every rank agreed on: delivers what is still held back
  /// (FieldRows: the row being summed). basalt-run's sink delivers on its own way out.
  virtual void deliver_pending() {}
};

}  // namespace basalt::solver
