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

namespace {
/// A number as fields.csv writes it: shortest round-trip text, nan / inf / -inf when not finite.
void put(std::string& out, double v) {
  if (std::isnan(v))
    out += "nan";  // one spelling, whatever the NaN's sign bit
  else if (std::isinf(v))
    out += v > 0 ? "inf" : "-inf";
  else
    fmt::format_to(std::back_inserter(out), "{}", v);
}
}  // namespace

void FieldSeriesWriter::append(std::int64_t step, double time, std::span<const double> values,
                               std::span<const double> due) {
  fmt::format_to(std::back_inserter(buffer_), "{},", step);
  put(buffer_, time);
  for (std::size_t c = 0; c < values.size(); ++c) {
    buffer_ += ',';
    if (due.empty() || due[c] > 0) put(buffer_, values[c]);  // empty cell: the saver was not due
  }
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
