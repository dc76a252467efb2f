#pragma once
// basalt-view plot: field-saver series against time, as a PNG through VTK's charts.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "options.hpp"

namespace basalt::view {

struct PlotOptions {
  std::filesystem::path input;
  std::filesystem::path output;
  std::vector<std::string> columns;                 ///< empty: every column after step,time
  std::optional<std::filesystem::path> units_from;  ///< scene TOML with [units] length/time/force
  std::string ylabel;                               ///< overrides the derived label
  std::string title;
  ImageSize size{1200, 800};
  bool quiet = false;
};

void plot(const PlotOptions& o);

}  // namespace basalt::view
