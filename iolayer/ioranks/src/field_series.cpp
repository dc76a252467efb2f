#include "field_series.hpp"

#include <mpi.h>

#include <fmt/format.h>

#include "basalt/io/geometry.hpp"

namespace basalt::io::detail {

FieldSeriesWriter::FieldSeriesWriter(std::filesystem::path file, const std::vector<std::string>& names)
    : file_(std::move(file)) {
  out_ = std::fopen(file_.c_str(), "w");
  if (!out_) throw FormatError(file_, "", "cannot open for writing (does the folder exist and is it writable?)");
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
  for (double v : values) fmt::format_to(std::back_inserter(buffer_), ",{}", v);
  buffer_ += '\n';
}

void FieldSeriesWriter::flush() {
  if (buffer_.empty()) return;
  const double t0 = MPI_Wtime();
  const bool ok = std::fwrite(buffer_.data(), 1, buffer_.size(), out_) == buffer_.size() && std::fflush(out_) == 0;
  seconds_ += MPI_Wtime() - t0;
  if (!ok) throw FormatError(file_, "", "write failed (disk full or file-size limit?)");
  bytes_ += buffer_.size();
  buffer_.clear();
}

}  // namespace basalt::io::detail
