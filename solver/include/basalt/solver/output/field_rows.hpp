#pragma once
// Field-saver rows for a caller that steps the simulation itself (tests, energy_drift, Python): an
// OutputSink that sums the compute ranks' partials and hands each reduced row to a FieldSink on rank 0.
// The sum of a step's row runs while the next step computes (AsyncSum) and is delivered at the next
// row, at deliver_pending() or at flush(). It writes no frames and reports no output errors.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "basalt/solver/output/field_sink.hpp"
#include "basalt/solver/output/output_sink.hpp"
#include "basalt/solver/parallel/communicator.hpp"

namespace basalt::solver {

class FieldRows final : public OutputSink {
 public:
  FieldRows(const Comm& comm, FieldSink* sink) : comm_(comm), sink_(sink) {}
  /// Where rows go from now on, the one still being summed included (may be null: rows are dropped).
  void retarget(FieldSink* sink) { sink_ = sink; }

  /// The FieldSink's own begin() is its owner's to call (with field_columns(scene)).
  void begin(const std::vector<std::string>&) override {}
  void fields(std::int64_t step, double time, std::span<const double> local_partials,
              std::span<const char> due) override;
  std::uint32_t frame_kinds(std::int64_t) const override { return 0; }
  void frame(const io::FrameSource&) override {}
  std::optional<std::string> poll() override { return std::nullopt; }
  bool continue_on_error() const override { return false; }
  /// Collective: delivers the row in flight and flushes the sink.
  void flush() override;
  void deliver_pending() override { flush(); }

  /// Collective: delivers the row whose sum is still in flight (more than one rank), if any.
  void finish();

 private:
  const Comm& comm_;
  FieldSink* sink_;
  std::unique_ptr<AsyncSum> sum_;  ///< the last row's reduction, finished at the next row
  std::int64_t step_ = 0;
  double time_ = 0;
  std::vector<char> due_;
};

}  // namespace basalt::solver
