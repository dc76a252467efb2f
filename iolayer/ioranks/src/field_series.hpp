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

  void append(std::int64_t step, double time, std::span<const double> values);
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
