#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/output/field_sink.hpp"

namespace basalt::solver {

namespace fs = std::filesystem;

CsvFieldSink::CsvFieldSink(const fs::path& dir) : path_(dir / "fields.csv") {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    throw InputError(fmt::format("{}: cannot create the output folder: {}", dir.string(), ec.message()));
  file_ = std::fopen(path_.c_str(), "w");
  if (!file_) throw InputError(fmt::format("{}: cannot write: {}", path_.string(), std::strerror(errno)));
}

CsvFieldSink::~CsvFieldSink() {
  if (!file_) return;
  try {
    flush();
  } catch (...) {
  }
  std::fclose(file_);
}

void CsvFieldSink::begin(const std::vector<std::string>& columns) {
  buffer_ = "step,time";
  for (const auto& c : columns) buffer_ += "," + c;
  buffer_ += '\n';
  flush();
}

void CsvFieldSink::row(std::int64_t step, double time, const std::vector<std::optional<double>>& values) {
  fmt::format_to(std::back_inserter(buffer_), "{},{:.17g}", step, time);
  for (const auto& v : values) {
    buffer_ += ',';
    if (v) fmt::format_to(std::back_inserter(buffer_), "{:.17g}", *v);
  }
  buffer_ += '\n';
  if (++pending_rows_ >= 256) flush();
}

void CsvFieldSink::flush() {
  if (!buffer_.empty()) {
    if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size() || std::fflush(file_) != 0)
      throw RunError(fmt::format("{}: write failed: {}", path_.string(), std::strerror(errno)));
  } else if (std::fflush(file_) != 0) {
    throw RunError(fmt::format("{}: write failed: {}", path_.string(), std::strerror(errno)));
  }
  buffer_.clear();
  pending_rows_ = 0;
}

}  // namespace basalt::solver
