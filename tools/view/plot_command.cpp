#include "plot_command.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>
#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <stdexcept>

#include "basalt/io/geometry.hpp"
#include "field_series.hpp"
#include "png_output.hpp"
#include "units.hpp"

namespace basalt::view {

namespace fs = std::filesystem;

namespace {

io::Units units_from_scene(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw io::FormatError(file, "", "no such file");
  toml::table scene;
  try {
    scene = toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw io::FormatError(file, fmt::format("line {}", e.source().begin.line), std::string(e.description()));
  }
  io::Units u;
  if (const toml::node* units = scene.get("units")) {
    const toml::table* t = units->as_table();
    if (t == nullptr) throw io::FormatError(file, "units", "expected a table [units]");
    for (auto [key, field] : {std::pair{"length", &u.length}, {"time", &u.time}, {"force", &u.force}}) {
      if (const toml::node* n = t->get(key)) {
        auto v = n->value<std::string>();
        if (!v) throw io::FormatError(file, fmt::format("units.{}", key), "expected a string such as \"mm\"");
        *field = *v;
      }
    }
  }
  return u;
}

std::string pretty(std::string name) {
  std::replace(name.begin(), name.end(), '_', ' ');
  return name;
}

std::string labelled(const std::string& column, const io::Units& u) {
  const std::string unit = quantity_units(column, u);
  return unit.empty() ? pretty(column) : fmt::format("{} ({})", pretty(column), unit);
}

}  // namespace

void plot(const PlotOptions& o) {
  require_writable(o.output.string());
  if (o.output.extension() != ".png")
    throw std::invalid_argument(fmt::format("output {}: plot writes PNG images (.png)", o.output.string()));
  const io::Units units = o.units_from ? units_from_scene(*o.units_from) : io::Units{};
  const FieldSeries series = read_field_series(o.input);

  std::vector<std::string> columns = o.columns;
  if (columns.empty()) columns.assign(series.names.begin() + 2, series.names.end());
  for (const auto& c : columns)
    if (series.column(c) < 2)
      throw std::invalid_argument(fmt::format("{}: no column \"{}\"; available: {}", o.input.string(), c,
                                              fmt::join(series.names.begin() + 2, series.names.end(), ", ")));

  auto table = vtkSmartPointer<vtkTable>::New();
  auto add_column = [&](const std::string& name) {
    auto a = vtkSmartPointer<vtkDoubleArray>::New();
    a->SetName(name.c_str());
    const auto& v = series.columns[static_cast<std::size_t>(series.column(name))];
    a->SetNumberOfTuples(static_cast<vtkIdType>(v.size()));
    std::copy(v.begin(), v.end(), a->GetPointer(0));
    table->AddColumn(a);
  };
  add_column("time");
  for (const auto& c : columns) add_column(c);

  auto view = vtkSmartPointer<vtkContextView>::New();
  vtkRenderWindow* window = view->GetRenderWindow();
  window->SetOffScreenRendering(1);
  window->SetSize(o.size.width, o.size.height);
  view->GetRenderer()->SetBackground(1, 1, 1);
  auto chart = vtkSmartPointer<vtkChartXY>::New();
  view->GetScene()->AddItem(chart);

  const int font = std::max(10, o.size.height / 32);
  static const unsigned char palette[][3] = {{31, 119, 180}, {214, 39, 40},   {44, 160, 44},
                                             {255, 127, 14}, {148, 103, 189}, {140, 86, 75}};
  for (std::size_t k = 0; k < columns.size(); ++k) {
    vtkPlot* line = chart->AddPlot(vtkChart::LINE);
    line->SetInputData(table, 0, static_cast<vtkIdType>(k + 1));
    const auto& c = palette[k % 6];
    line->SetColor(c[0], c[1], c[2], 255);
    line->SetWidth(2.0f);
    line->SetLabel(labelled(columns[k], units));
  }
  std::string ylabel = o.ylabel;
  if (ylabel.empty()) {
    if (columns.size() == 1) {
      ylabel = labelled(columns[0], units);
    } else {
      // Several columns: one unit if they share it, else leave the units to the legend.
      const std::string u0 = quantity_units(columns[0], units);
      const bool same = std::all_of(columns.begin(), columns.end(),
                                    [&](const std::string& c) { return quantity_units(c, units) == u0; });
      ylabel = same && !u0.empty() ? fmt::format("value ({})", u0) : "value";
    }
  }
  vtkAxis* x = chart->GetAxis(vtkAxis::BOTTOM);
  vtkAxis* y = chart->GetAxis(vtkAxis::LEFT);
  x->SetTitle(fmt::format("time ({})", units.time));
  y->SetTitle(ylabel);
  for (vtkAxis* a : {x, y}) {
    a->GetTitleProperties()->SetFontSize(font);
    a->GetTitleProperties()->BoldOff();
    a->GetLabelProperties()->SetFontSize(font * 5 / 6);
  }
  if (!o.title.empty()) {
    chart->SetTitle(o.title);
    chart->GetTitleProperties()->SetFontSize(font * 6 / 5);
  }
  chart->SetShowLegend(columns.size() > 1);
  chart->GetLegend()->GetLabelProperties()->SetFontSize(font * 5 / 6);

  window->Render();
  write_png(*window, o.output);
  if (!o.quiet)
    fmt::print("wrote {} ({}x{}, {} rows, columns {})\n", o.output.string(), o.size.width, o.size.height,
               series.rows(), fmt::join(columns, ","));
}

}  // namespace basalt::view
