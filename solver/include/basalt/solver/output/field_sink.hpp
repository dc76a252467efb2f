#pragma once
// Where field-saver rows go. The solver only sees this interface; today rank 0 writes a CSV file
// synchronously (CsvFieldSink), later I/O ranks will take the rows over MPI.
#include <cstdint>
#include <filesystem>
#include <memory>
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

/// DIR/fields.csv: header "step,time,<columns>", one row per saved step, full double precision.
/// Throws InputError naming the file when it cannot be created or written.
class CsvFieldSink final : public FieldSink {
 public:
  explicit CsvFieldSink(const std::filesystem::path& dir);
  ~CsvFieldSink() override;
  void begin(const std::vector<std::string>& columns) override;
  void row(std::int64_t step, double time, const std::vector<std::optional<double>>& values) override;
  void flush() override;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  std::string buffer_;
  int pending_rows_ = 0;
};

}  // namespace basalt::solver
