// basalt-view's input parsing: option values, field-series CSV, units. Pure functions, no X needed.
#include <gtest/gtest.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include "basalt/io/geometry.hpp"
#include "color_field.hpp"
#include "convert_command.hpp"
#include "field_series.hpp"
#include "options.hpp"
#include "particle_selection.hpp"
#include "render_command.hpp"
#include "test_support.hpp"
#include "units.hpp"

namespace fs = std::filesystem;
using namespace basalt::view;

namespace {

fs::path write_file(const fs::path& dir, const std::string& name, const std::string& text) {
  std::ofstream(dir / name) << text;
  return dir / name;
}

std::string error_of(const fs::path& csv) {
  try {
    read_field_series(csv);
  } catch (const basalt::io::FormatError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(ViewOptions, SizeRangeCutView) {
  EXPECT_EQ(parse_size("1600x1200").width, 1600);
  EXPECT_EQ(parse_size("1600x1200").height, 1200);
  for (const char* bad : {"1600", "x1200", "1600x", "16OOx1200", "1600x1200x3", "8x8", "-5x100"})
    EXPECT_THROW(parse_size(bad), std::invalid_argument) << bad;

  EXPECT_EQ(parse_range("-1:2").min, -1.0);
  EXPECT_EQ(parse_range("-1:2").max, 2.0);
  EXPECT_EQ(parse_range("1e-3:5e-2").min, 1e-3);
  EXPECT_EQ(parse_range("-2:-1").max, -1.0);
  for (const char* bad : {"1", "2:1", "1:1", "a:b", "1:2x", ":"})
    EXPECT_THROW(parse_range(bad), std::invalid_argument) << bad;

  EXPECT_EQ(parse_cut("y").axis, 1);
  EXPECT_FALSE(parse_cut("y").value.has_value());
  EXPECT_EQ(parse_cut("z:7.5").axis, 2);
  EXPECT_EQ(*parse_cut("z:7.5").value, 7.5);
  for (const char* bad : {"w", "x:", "x7", "xy", "z:abc", ""})
    EXPECT_THROW(parse_cut(bad), std::invalid_argument) << bad;

  EXPECT_EQ(parse_view("-y").toward_camera[1], -1.0);
  EXPECT_EQ(parse_view("+z").up[1], 1.0);  // looking down z, y is up
  EXPECT_EQ(parse_view("iso").up[2], 1.0);
  for (const char* bad : {"x", "+w", "top", "++x"})
    EXPECT_THROW(parse_view(bad), std::invalid_argument) << bad;
}

TEST(ViewOptions, UnwritableOutputIsRefusedBeforeAnyWork) {
  const fs::path dir = basalt::test::scratch_dir("view-writable");
  EXPECT_NO_THROW(require_writable((dir / "a.png").string()));
  EXPECT_THROW(require_writable((dir / "missing" / "a.png").string()), std::invalid_argument);
  EXPECT_THROW(require_writable(dir.string()), std::invalid_argument);  // a folder
}

TEST(FieldSeriesCsv, ReadsColumnsInOrder) {
  const fs::path dir = basalt::test::scratch_dir("view-csv");
  const auto f =
      write_file(dir, "fields.csv",
                 "step,time,kinetic_energy,wall_force\n0,0,0,1e-3\n\n100,0.1,2.5e-4,-3\r\n200,0.2,1.25,7\n");
  const FieldSeries s = read_field_series(f);
  ASSERT_EQ(s.names.size(), 4u);
  EXPECT_EQ(s.names[2], "kinetic_energy");
  ASSERT_EQ(s.rows(), 3u);
  EXPECT_EQ(s.columns[1][1], 0.1);
  EXPECT_EQ(s.columns[2][1], 2.5e-4);
  EXPECT_EQ(s.columns[3][1], -3.0);
  EXPECT_EQ(s.column("wall_force"), 3);
  EXPECT_EQ(s.column("nope"), -1);
}

TEST(FieldSeriesCsv, MalformedLinesAreNamedByNumber) {
  const fs::path dir = basalt::test::scratch_dir("view-csv-bad");
  const std::string header = "step,time,kinetic_energy\n";
  auto err = error_of(write_file(dir, "a.csv", header + "0,0,1\n1,0.1,abc\n"));
  EXPECT_NE(err.find("a.csv: line 3"), std::string::npos) << err;
  EXPECT_NE(err.find("kinetic_energy"), std::string::npos) << err;
  err = error_of(write_file(dir, "b.csv", header + "0,0,1\n1,0.1\n"));
  EXPECT_NE(err.find("b.csv: line 3"), std::string::npos) << err;
  EXPECT_NE(err.find("2 values, expected 3"), std::string::npos) << err;
  err = error_of(write_file(dir, "c.csv", header + "0,0,1,5\n"));
  EXPECT_NE(err.find("c.csv: line 2"), std::string::npos) << err;
  err = error_of(write_file(dir, "d.csv", header + "0,0,1.5.2\n"));
  EXPECT_NE(err.find("d.csv: line 2"), std::string::npos) << err;
  err = error_of(write_file(dir, "e.csv", "time,step,ke\n0,0,1\n"));
  EXPECT_NE(err.find("e.csv: line 1"), std::string::npos) << err;
  err = error_of(write_file(dir, "f.csv", header));
  EXPECT_NE(err.find("no data rows"), std::string::npos) << err;
  err = error_of(write_file(dir, "g.csv", ""));
  EXPECT_NE(err.find("empty file"), std::string::npos) << err;
  // A field may be nan or inf (the solver writes them so; plot skips them), step and time may not.
  err = error_of(write_file(dir, "h.csv", header + "0,nan,1\n"));
  EXPECT_NE(err.find("h.csv: line 2"), std::string::npos) << err;
  err = error_of(write_file(dir, "i.csv", header + "0,0,1\n1,0.1,1e999\n"));  // beyond double: not inf
  EXPECT_NE(err.find("i.csv: line 3"), std::string::npos) << err;
  err = error_of(write_file(dir, "j.csv", header + "0,,1\n"));  // only a field's cell may be empty
  EXPECT_NE(err.find("j.csv: line 2"), std::string::npos) << err;
  err = error_of(dir / "missing.csv");
  EXPECT_NE(err.find("missing.csv: no such file"), std::string::npos) << err;
}

TEST(ViewUnits, DerivedFromLengthTimeForce) {
  const basalt::io::Units mm_ms_n;
  EXPECT_EQ(quantity_units("kinetic_energy", mm_ms_n), "N\u00b7mm = mJ");
  EXPECT_EQ(quantity_units("speed", mm_ms_n), "mm/ms");
  EXPECT_EQ(quantity_units("velocity", mm_ms_n), "mm/ms");
  EXPECT_EQ(quantity_units("radius", mm_ms_n), "mm");
  EXPECT_EQ(quantity_units("displacement", mm_ms_n), "mm");
  EXPECT_EQ(quantity_units("mass", mm_ms_n), "g");
  EXPECT_EQ(quantity_units("wall_force", mm_ms_n), "N");
  EXPECT_EQ(quantity_units("id", mm_ms_n), "");
  EXPECT_EQ(quantity_units("tag", mm_ms_n), "");
  basalt::io::Units si{"m", "s", "N", ""};
  EXPECT_EQ(quantity_units("kinetic_energy", si), "N\u00b7m = J");
  EXPECT_EQ(quantity_units("mass", si), "kg");
  EXPECT_EQ(quantity_units("speed", si), "m/s");
}

TEST(ParticleSelection, BuriedParticlesAreDroppedAndTheSurfaceKept) {
  // A 20^3 lattice with spacing 1 and radius 0.5; cell = 2 x radius = 1 lattice spacing.
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  auto pts = vtkSmartPointer<vtkPoints>::New();
  for (int k = 0; k < 20; ++k)
    for (int j = 0; j < 20; ++j)
      for (int i = 0; i < 20; ++i) pts->InsertNextPoint(i, j, k);
  pd->SetPoints(pts);
  std::vector<vtkIdType> all(8000);
  for (vtkIdType i = 0; i < 8000; ++i) all[static_cast<std::size_t>(i)] = i;
  const auto kept = drop_buried(*pd, all, 1.0);
  // Kept: closer than one cell to a face (the outer layer, 20^3 - 18^3), nothing deeper.
  EXPECT_EQ(kept.size(), 8000u - 18 * 18 * 18);
  for (vtkIdType i : kept) {
    const double* p = pd->GetPoint(i);
    const double depth = std::min({p[0], p[1], p[2], 19 - p[0], 19 - p[1], 19 - p[2]});
    EXPECT_LT(depth, 1.0);
  }
  // A hole (an empty cell) inside exposes its neighbours: they are kept.
  std::vector<vtkIdType> holed;
  const vtkIdType hole = (10 * 20 + 10) * 20 + 10;
  for (vtkIdType i : all)
    if (i != hole) holed.push_back(i);
  const auto kept_holed = drop_buried(*pd, holed, 1.0);
  EXPECT_EQ(kept_holed.size(), kept.size() + 26);

  // The cut keeps the far half from the camera: seen from +x, x <= 9.5.
  Cut cut;
  const auto half = cut_indices(*pd, cut, parse_view("+x"));
  EXPECT_EQ(half.size(), 4000u);
  for (vtkIdType i : half) EXPECT_LE(pd->GetPoint(i)[0], 9.5);
  EXPECT_EQ(select_points(*pd, half)->GetNumberOfVerts(), 4000);
}

TEST(FieldSeriesCsv, NonFiniteValuesAndSaversNotDueAreRead) {
  // Issue 16: a CSV with inf made an empty chart; nan was refused although the solver writes it for a
  // non-finite sum; an empty cell (a saver not due, docs/scenes.md) was refused as "not a number".
  const fs::path dir = basalt::test::scratch_dir("view-csv-nonfinite");
  const auto f =
      write_file(dir, "fields.csv",
                 "step,time,kinetic_energy,wall_force\n0,0,inf,1\n\n1,0.1,-inf,\n2,0.2,nan,3\n3,inf,4,5\n");
  const FieldSeries s = read_field_series(f);
  ASSERT_EQ(s.rows(), 4u);
  EXPECT_EQ(s.columns[2][0], std::numeric_limits<double>::infinity());
  EXPECT_EQ(s.columns[2][1], -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(s.columns[2][2]));
  EXPECT_FALSE(s.blank[2][2]);
  EXPECT_TRUE(std::isnan(s.columns[3][1]));
  EXPECT_TRUE(s.blank[3][1]);
  EXPECT_EQ(s.columns[1][3], std::numeric_limits<double>::infinity());
  EXPECT_EQ(s.lines, (std::vector<int>{2, 4, 5, 6}));  // the blank line 3 is skipped
}

// ---- issue 15: a colour range that outliers do not squeeze, series in step order ----------------------

TEST(ColourScale, PercentilesIgnoreAFewOutliersAndReportTheTrueExtremes) {
  // 1000 values 0.000 .. 0.999 (the bulk) and 5 fast particles at 45: p1..p99 stays near the bulk.
  std::vector<double> v;
  for (int i = 0; i < 1000; ++i) v.push_back(i / 1000.0);
  for (int i = 0; i < 5; ++i) v.push_back(45.0);
  v.push_back(std::numeric_limits<double>::quiet_NaN());  // ignored
  const ColourScale s = robust_scale(v);
  EXPECT_EQ(s.how, "p1-p99, clamped");
  EXPECT_NEAR(s.range.min, 0.01, 1e-3);
  EXPECT_LT(s.range.max, 1.0);  // the 5 outliers (0.5 %) lie above p99
  EXPECT_GT(s.range.max, 0.98);
  EXPECT_EQ(s.min, 0.0);
  EXPECT_EQ(s.max, 45.0);

  // Interpolated like numpy.percentile: 0..100 gives exactly 1 and 99.
  std::vector<double> w;
  for (int i = 100; i >= 0; --i) w.push_back(i);
  EXPECT_DOUBLE_EQ(robust_scale(w).range.min, 1.0);
  EXPECT_DOUBLE_EQ(robust_scale(w).range.max, 99.0);
}

TEST(ColourScale, FallsBackToTheFullRangeAndPadsAConstantField) {
  // 99.5 % of the particles at rest, a few moving: p1 == p99, so the full range is used.
  std::vector<double> v(1000, 0.0);
  for (int i = 0; i < 5; ++i) v.push_back(0.2);
  ColourScale s = robust_scale(v);
  EXPECT_EQ(s.how, "full range");
  EXPECT_EQ(s.range.min, 0.0);
  EXPECT_EQ(s.range.max, 0.2);

  s = robust_scale(std::vector<double>(10, 2.0));
  EXPECT_LT(s.range.min, 2.0);
  EXPECT_GT(s.range.max, 2.0);
  EXPECT_EQ(s.min, 2.0);
  EXPECT_THROW(robust_scale({std::numeric_limits<double>::infinity()}), std::invalid_argument);
  EXPECT_THROW(robust_scale({}), std::invalid_argument);

  s = given_scale({0, 1}, {-3, 0.5, 7});
  EXPECT_EQ(s.how, "--range, clamped");
  EXPECT_EQ(s.range.max, 1.0);
  EXPECT_EQ(s.min, -3.0);
  EXPECT_EQ(s.max, 7.0);
}

TEST(RenderSeries, CheckpointsOfAFolderInStepOrder) {
  const fs::path dir = basalt::test::scratch_dir("view-ckpt-order");
  for (const char* name : {"ckpt_1000.h5", "ckpt_000200.h5", "ckpt_30.h5", "ckpt_40.h5.partial", "ckpt_x.h5",
                           "geometry.h5", "ckpt_.h5"})
    std::ofstream(dir / name) << "x";
  const auto found = checkpoints_in(dir);
  ASSERT_EQ(found.size(), 3u);
  EXPECT_EQ(found[0].filename(), "ckpt_30.h5");
  EXPECT_EQ(found[1].filename(), "ckpt_000200.h5");
  EXPECT_EQ(found[2].filename(), "ckpt_1000.h5");
  EXPECT_TRUE(checkpoints_in(dir / "missing").empty());
}

TEST(ViewConvert, GeoToH5AndBackKeepsEveryValue) {
  // basalt-view convert in.geo -o out.h5: the HDF5 basalt-run's ranks read in slices, with the same values.
  namespace fs = std::filesystem;
  const fs::path dir = basalt::test::scratch_dir("view-convert-geo");
  const fs::path geo = basalt::test::reference_dir() / "cube1.geo";
  basalt::view::ConvertOptions o;
  o.inputs = {geo};
  o.output = dir / "cube1.h5";
  o.quiet = true;
  basalt::view::convert(o);
  const auto a = basalt::io::read_geometry(geo), b = basalt::io::read_geometry(dir / "cube1.h5");
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.radius, b.radius);
  EXPECT_EQ(a.tag, b.tag);
  EXPECT_EQ(a.bonds, b.bonds);
  o.inputs = {dir / "cube1.h5"};
  o.output = dir / "back.geo";
  basalt::view::convert(o);
  EXPECT_EQ(basalt::io::read_geometry(dir / "back.geo").position, a.position);
  o.inputs = {geo, geo};
  o.output = dir / "two.h5";
  EXPECT_THROW(basalt::view::convert(o), std::invalid_argument);
}
