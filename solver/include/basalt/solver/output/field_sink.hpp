#pragma once
// Where reduced field-saver rows go when a caller steps the simulation itself (tests collect them in
// memory). basalt-run's output goes through OutputSink (output_sink.hpp) instead, to the
// I/O ranks or the synchronous writer.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace basalt::solver {

class FieldSink {
 public:
  virtual ~FieldSink() = default;
  /// Column names after "step" and "time".
  virtual void begin(const std::vector<std::string>& columns) = 0;
  /// One row; an empty optional is a saver not due at this step (empty cell).
  virtual void row(std::int64_t step, double time, const std::vector<std::optional<double>>& values) = 0;
  /// Makes everything written so far durable (end of run, or before reporting an error).
  virtual void flush() = 0;
};

}  // namespace basalt::solver
