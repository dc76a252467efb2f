#pragma once
// fields.csv: a header naming the columns (step, time, one per saver), one row per saved step.
// Rows are flushed every batch so a crash loses at most the rows not yet handed over.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace basalt::io::detail {

class FieldSeriesWriter {
 public:
  /// With `append`, continues an existing file (a restart): no header, rows go after its last line.
  FieldSeriesWriter(std::filesystem::path file, const std::vector<std::string>& names, bool append = false);
  ~FieldSeriesWriter();
  FieldSeriesWriter(const FieldSeriesWriter&) = delete;
  FieldSeriesWriter& operator=(const FieldSeriesWriter&) = delete;

  /// One row. A column whose due flag is 0 is an empty cell (saver not due); a due value that is not
  /// finite is written as nan, inf or -inf.
  void append(std::int64_t step, double time, std::span<const double> values, std::span<const double> due);
  /// One row [step, time, due_1 .. due_n, v_1 .. v_n] as it travels (due > 0: due).
  void append_wire_row(const double* row, std::size_t n_fields) {
    append(static_cast<std::int64_t>(row[0]), row[1], std::span<const double>(row + 2 + n_fields, n_fields),
           std::span<const double>(row + 2, n_fields));
  }
  void flush();  ///< throws FormatError naming the file when the disk refuses
  std::uint64_t bytes() const { return bytes_; }
  double seconds() const { return seconds_; }

 private:
  std::filesystem::path file_;
  std::FILE* out_ = nullptr;
  std::string buffer_;
  std::uint64_t bytes_ = 0;
  double seconds_ = 0;
};

}  // namespace basalt::io::detail
