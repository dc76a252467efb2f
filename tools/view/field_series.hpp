#pragma once
// Field-saver series: CSV "step,time,<one column per saver>" then numeric rows.
#include <filesystem>
#include <string>
#include <vector>

namespace basalt::view {

struct FieldSeries {
  std::vector<std::string> names;            ///< header, starting with step, time
  std::vector<std::vector<double>> columns;  ///< one vector per header name, all of the same length
  /// Per column, per row: the cell was empty ("saver not due", docs/scenes.md); its value is NaN.
  std::vector<std::vector<bool>> blank;
  std::vector<int> lines;  ///< the file's line number of each row
  std::size_t rows() const { return columns.empty() ? 0 : columns[0].size(); }
  /// Index of a column, or -1.
  int column(const std::string& name) const;
};

/// Reads and checks a series. Throws io::FormatError naming the file and line for a header not
/// starting with step,time, a non-numeric value, a wrong number of columns, or no data rows.
/// `nan`, `inf` and `-inf` are values (the solver writes non-finite sums so); an empty field cell is a
/// saver not due on that row (NaN, marked in `blank`); step and time must be present.
FieldSeries read_field_series(const std::filesystem::path& file);

}  // namespace basalt::view
