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
#include <vtkPlotPoints.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
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

namespace {

/// The rows of one column that can be drawn (time and value finite), and what was left out.
struct Drawable {
  std::vector<double> t, v;
  std::size_t not_due = 0;
  std::vector<std::string> skipped;  ///< "line 7: inf" for each row left out for a non-finite number
};

Drawable drawable(const FieldSeries& s, int column) {
  const auto& time = s.columns[1];
  const auto& val = s.columns[static_cast<std::size_t>(column)];
  const auto& blank = s.blank[static_cast<std::size_t>(column)];
  Drawable d;
  for (std::size_t i = 0; i < val.size(); ++i) {
    if (blank[i]) {
      ++d.not_due;
    } else if (std::isfinite(time[i]) && std::isfinite(val[i])) {
      d.t.push_back(time[i]);
      d.v.push_back(val[i]);
    } else {
      d.skipped.push_back(std::isfinite(time[i]) ? fmt::format("line {}: {}", s.lines[i], val[i])
                                                 : fmt::format("line {}: time {}", s.lines[i], time[i]));
    }
  }
  return d;
}

std::string listed(const std::vector<std::string>& items) {
  constexpr std::size_t kShown = 3;
  std::string out;
  for (std::size_t i = 0; i < std::min(items.size(), kShown); ++i) out += (i ? ", " : "") + items[i];
  if (items.size() > kShown) out += fmt::format(", ... ({} in all)", items.size());
  return out;
}

/// VTK's charts draw in single precision, and an axis from -1e308 to 1e308 has an infinite length: an
/// axis whose values reach beyond 1e30 (or stay below 1e-30) is drawn in units of a power of ten.
int decade_of(const std::vector<const std::vector<double>*>& data) {
  double top = 0;
  for (const auto* d : data)
    for (double x : *d) top = std::max(top, std::abs(x));
  if (top == 0 || (top < 1e30 && top > 1e-30)) return 0;
  return static_cast<int>(std::floor(std::log10(top)));
}

void rescale(std::vector<double>& v, int decade) {
  if (decade == 0) return;
  // 10^-decade in two halves, so that neither overflows (decade up to 308, down to -323).
  const double a = std::pow(10.0, -(decade / 2)), b = std::pow(10.0, -(decade - decade / 2));
  for (double& x : v) x = x * a * b;
}

std::string in_units_of(int decade) { return decade == 0 ? "" : fmt::format(" [x 1e{}]", decade); }

/// An axis over a single value (one row, a constant column) has no length: give it one.
void fix_degenerate(vtkAxis* axis, const std::vector<const std::vector<double>*>& data) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto* d : data)
    for (double x : *d) {
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
  if (!(lo == hi)) return;
  const double pad = lo == 0 ? 1.0 : 0.1 * std::abs(lo);
  axis->SetBehavior(vtkAxis::FIXED);
  axis->SetRange(lo - pad, hi + pad);
}

}  // namespace

void plot(const PlotOptions& o) {
  require_writable(o.output.string());
  if (o.output.extension() != ".png")
    throw std::invalid_argument(fmt::format("output {}: plot writes PNG images (.png)", o.output.string()));
  const io::Units units = o.units_from ? units_from_scene(*o.units_from) : io::Units{};
  const FieldSeries series = read_field_series(o.input);

  std::vector<std::string> requested = o.columns;
  if (requested.empty()) requested.assign(series.names.begin() + 2, series.names.end());
  for (const auto& c : requested)
    if (series.column(c) < 2)
      throw std::invalid_argument(fmt::format("{}: no column \"{}\"; available: {}", o.input.string(), c,
                                              fmt::join(series.names.begin() + 2, series.names.end(), ", ")));

  // Only finite points are drawn; say what was left out, and refuse a chart with nothing on it.
  std::vector<std::string> columns, empty;
  std::vector<Drawable> data;
  for (const auto& c : requested) {
    Drawable d = drawable(series, series.column(c));
    if (d.t.empty()) {
      empty.push_back(fmt::format(
          "column \"{}\": nothing to draw ({})", c,
          d.skipped.empty()
              ? fmt::format("every one of its {} rows is empty: the saver was never due", d.not_due)
              : fmt::format("no finite value: {}", listed(d.skipped))));
      continue;
    }
    if (!d.skipped.empty())
      std::fprintf(
          stderr, "basalt-view: warning: %s: column \"%s\": %zu of %zu rows not drawn, not finite (%s)\n",
          o.input.string().c_str(), c.c_str(), d.skipped.size(), series.rows(), listed(d.skipped).c_str());
    columns.push_back(c);
    data.push_back(std::move(d));
  }
  if (columns.empty())
    throw io::FormatError(o.input, "", fmt::format("{}; no chart written", fmt::join(empty, "; ")));
  for (const auto& e : empty)
    std::fprintf(stderr, "basalt-view: warning: %s: %s: left out of the chart\n", o.input.string().c_str(),
                 e.c_str());

  std::vector<const std::vector<double>*> xs, ys;
  for (const auto& d : data) {
    xs.push_back(&d.t);
    ys.push_back(&d.v);
  }
  const int x_decade = decade_of(xs), y_decade = decade_of(ys);
  for (auto& d : data) {
    rescale(d.t, x_decade);
    rescale(d.v, y_decade);
  }

  // One table per column: each has its own finite rows.
  std::vector<vtkSmartPointer<vtkTable>> tables;
  auto array_of = [](const std::string& name, const std::vector<double>& v) {
    auto a = vtkSmartPointer<vtkDoubleArray>::New();
    a->SetName(name.c_str());
    a->SetNumberOfTuples(static_cast<vtkIdType>(v.size()));
    std::copy(v.begin(), v.end(), a->GetPointer(0));
    return a;
  };
  for (std::size_t k = 0; k < columns.size(); ++k) {
    auto table = vtkSmartPointer<vtkTable>::New();
    table->AddColumn(array_of("time", data[k].t));
    table->AddColumn(array_of(columns[k], data[k].v));
    tables.push_back(table);
  }

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
    // A line needs two points: a lone one is drawn as a marker.
    const bool lone = data[k].t.size() < 2;
    vtkPlot* line = chart->AddPlot(lone ? vtkChart::POINTS : vtkChart::LINE);
    line->SetInputData(tables[k], 0, 1);
    const auto& c = palette[k % 6];
    line->SetColor(c[0], c[1], c[2], 255);
    line->SetWidth(2.0f);
    line->SetLabel(labelled(columns[k], units));
    if (lone)
      if (auto* points = vtkPlotPoints::SafeDownCast(line)) {
        points->SetMarkerStyle(vtkPlotPoints::CIRCLE);
        points->SetMarkerSize(static_cast<float>(std::max(12, font)));
      }
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
  x->SetTitle(fmt::format("time ({}){}", units.time, in_units_of(x_decade)));
  y->SetTitle(ylabel + in_units_of(y_decade));
  fix_degenerate(x, xs);
  fix_degenerate(y, ys);
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
