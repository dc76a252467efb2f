#include "field_series.hpp"

#include <fmt/format.h>
#include <mpi.h>

#include <cmath>

#include "basalt/io/geometry.hpp"

namespace basalt::io::detail {

FieldSeriesWriter::FieldSeriesWriter(std::filesystem::path file, const std::vector<std::string>& names,
                                     bool append)
    : file_(std::move(file)) {
  const bool resume = append && std::filesystem::exists(file_);
  out_ = std::fopen(file_.c_str(), resume ? "a" : "w");
  if (!out_)
    throw FormatError(file_, "", "cannot open for writing (does the folder exist and is it writable?)");
  if (resume) return;
  buffer_ = "step,time";
  for (const auto& n : names) buffer_ += "," + n;
  buffer_ += "\n";
  flush();
}

FieldSeriesWriter::~FieldSeriesWriter() {
  if (!out_) return;
  try {
    flush();
  } catch (...) {
  }
  std::fclose(out_);
}

void FieldSeriesWriter::append(std::int64_t step, double time, std::span<const double> values) {
  fmt::format_to(std::back_inserter(buffer_), "{},{}", step, time);
  // NaN marks a saver not due at this step: an empty cell.
  for (double v : values)
    if (std::isnan(v))
      buffer_ += ',';
    else
      fmt::format_to(std::back_inserter(buffer_), ",{}", v);
  buffer_ += '\n';
}

void FieldSeriesWriter::flush() {
  if (buffer_.empty()) return;
  const double t0 = MPI_Wtime();
  const bool ok =
      std::fwrite(buffer_.data(), 1, buffer_.size(), out_) == buffer_.size() && std::fflush(out_) == 0;
  seconds_ += MPI_Wtime() - t0;
  if (!ok) throw FormatError(file_, "", "write failed (disk full or file-size limit?)");
  bytes_ += buffer_.size();
  buffer_.clear();
}

}  // namespace basalt::io::detail
