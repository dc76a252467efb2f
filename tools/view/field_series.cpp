#include "field_series.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <system_error>

#include "basalt/io/geometry.hpp"

namespace basalt::view {

namespace fs = std::filesystem;

int FieldSeries::column(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  return -1;
}

namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    std::string cell = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const auto b = cell.find_first_not_of(" \t");
    const auto e = cell.find_last_not_of(" \t");
    out.push_back(b == std::string::npos ? std::string() : cell.substr(b, e - b + 1));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

FieldSeries read_field_series(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw io::FormatError(file, "", "no such file");
  std::ifstream in(file);
  if (!in) throw io::FormatError(file, "", "cannot open for reading");
  FieldSeries s;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;  // blank lines
    const std::string where = fmt::format("line {}", number);
    std::vector<std::string> cells = split(line);
    if (s.names.empty()) {
      if (cells.size() < 3 || cells[0] != "step" || cells[1] != "time")
        throw io::FormatError(file, where,
                              fmt::format("header must be \"step,time,<field>...\", found \"{}\"", line));
      for (const auto& c : cells)
        if (c.empty()) throw io::FormatError(file, where, "empty column name in header");
      s.names = cells;
      s.columns.resize(cells.size());
      s.blank.resize(cells.size());
      continue;
    }
    if (cells.size() != s.names.size())
      throw io::FormatError(
          file, where,
          fmt::format("{} values, expected {} ({})", cells.size(), s.names.size(), fmt::join(s.names, ",")));
    for (std::size_t i = 0; i < cells.size(); ++i) {
      double v = std::numeric_limits<double>::quiet_NaN();
      const std::string& c = cells[i];
      if (c.empty() && i >= 2) {  // a saver not due on this row
        s.columns[i].push_back(v);
        s.blank[i].push_back(true);
        continue;
      }
      // from_chars reads nan, inf and infinity (any case); a number beyond the double range (1e999) is
      // an error, refused as not a number rather than read as inf.
      const auto [ptr, err] = std::from_chars(c.data(), c.data() + c.size(), v);
      if (c.empty() || err != std::errc() || ptr != c.data() + c.size() || (i < 2 && std::isnan(v)))
        throw io::FormatError(file, where,
                              fmt::format("column \"{}\": \"{}\" is not a number", s.names[i], c));
      s.columns[i].push_back(v);
      s.blank[i].push_back(false);
    }
    s.lines.push_back(number);
  }
  if (s.names.empty())
    throw io::FormatError(file, "line 1", "empty file: expected a header \"step,time,...\"");
  if (s.rows() == 0) throw io::FormatError(file, "", "no data rows after the header");
  return s;
}

}  // namespace basalt::view
