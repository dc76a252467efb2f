// basalt-view end to end: the command run as a user would, without DISPLAY (it starts its own
// virtual X server), its outputs checked through VTK's readers: PNG size and content, VTK frames.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPolyDataReader.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>

#include "basalt/io/checkpoint.hpp"
#include "basalt/io/vtk_frames.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using basalt::io::Vec3;

namespace {

/// Quotes each argument but the last, which holds plain options (split by the shell).
template <class... Args>
std::string fmt_args(const Args&... parts) {
  std::string out;
  const std::string all[] = {std::string(parts)...};
  for (std::size_t i = 0; i < sizeof...(parts); ++i) {
    const bool options = i + 1 == sizeof...(parts) && all[i].rfind("--", 0) == 0;
    out += options ? all[i] : "'" + all[i] + "'";
    out += " ";
  }
  return out;
}

struct Outcome {
  int code = -1;
  std::string out;  ///< stdout and stderr together
};

Outcome basalt_view(const std::string& args, const fs::path& dir, const std::string& env = "") {
  const fs::path log = dir / "basalt-view.log";
  const std::string cmd =
      fmt::format("env -u DISPLAY {} {} {} > '{}' 2>&1", env, BASALT_VIEW_EXE, args, log.string());
  const int status = std::system(cmd.c_str());
  Outcome r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  std::ifstream in(log);
  std::stringstream s;
  s << in.rdbuf();
  r.out = s.str();
  return r;
}

using Rgb = std::array<int, 3>;

struct Image {
  int width = 0, height = 0;
  std::vector<Rgb> pixels;  ///< row 0 at the bottom (VTK's order)
  /// Pixels whose x < x_max_fraction * width and whose colour is within `tol` of `c` in every channel.
  int count(const Rgb& c, int tol, double x_max_fraction = 1.0) const {
    int n = 0;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < static_cast<int>(x_max_fraction * width); ++x) {
        const Rgb& p = pixels[static_cast<std::size_t>(y * width + x)];
        if (std::abs(p[0] - c[0]) <= tol && std::abs(p[1] - c[1]) <= tol && std::abs(p[2] - c[2]) <= tol) ++n;
      }
    return n;
  }
  /// The same for the pixels with x0_fraction * width <= x < x1_fraction * width.
  int count_between(const Rgb& c, int tol, double x0_fraction, double x1_fraction) const {
    return count(c, tol, x1_fraction) - count(c, tol, x0_fraction);
  }
};

Image read_png(const fs::path& file) {
  auto reader = vtkSmartPointer<vtkPNGReader>::New();
  Image img;
  if (!reader->CanReadFile(file.c_str())) return img;
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkImageData* data = reader->GetOutput();
  int dims[3];
  data->GetDimensions(dims);
  img.width = dims[0];
  img.height = dims[1];
  vtkDataArray* s = data->GetPointData()->GetScalars();
  for (vtkIdType i = 0; i < s->GetNumberOfTuples(); ++i)
    img.pixels.push_back({static_cast<int>(s->GetComponent(i, 0)), static_cast<int>(s->GetComponent(i, 1)),
                          static_cast<int>(s->GetComponent(i, 2))});
  return img;
}

// basalt-view's scene: background and the ends of its cool-to-warm colour map, in 0..255.
const Rgb kBackground{82, 87, 110};
const Rgb kLow{59, 76, 192};
const Rgb kHigh{180, 4, 38};
const double kSceneFraction = 0.8;  // the colour bar sits in the right 16 % of the image

vtkSmartPointer<vtkPolyData> read_vtp(const fs::path& file) {
  auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  reader->SetFileName(file.c_str());
  reader->Update();
  return reader->GetOutput();
}

/// A 12x12x12 lattice of touching spheres moving upward, faster with height (a wave front).
basalt::io::Checkpoint lattice_checkpoint() {
  basalt::io::Checkpoint c;
  for (int k = 0; k < 12; ++k)
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 12; ++i) {
        c.geometry.add_particle(k * 144 + j * 12 + i, {1.0 * i, 1.0 * j, 1.0 * k}, 0.5, k % 2);
        c.velocity.push_back({0, 0, 0.01 * k});
      }
  c.geometry.mass.assign(c.geometry.size(), 0.5);
  c.step = 3400;
  c.time = 3.4;
  return c;
}

}  // namespace

TEST(BasaltView, RendersGeometryWithCutAtRequestedSizeAndBothEndsOfTheMap) {
  const fs::path dir = basalt::test::scratch_dir("view-render-geo");
  const fs::path geo = basalt::test::reference_dir() / "cube1.geo";
  ASSERT_TRUE(fs::exists(geo)) << geo;
  const Outcome r = basalt_view(fmt_args("render", geo.string(), "-o", (dir / "cube.png").string(),
                                         "--color radius --cut x --size 480x360"),
                                dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_FALSE(fs::exists(dir / "cube.png.partial"));
  const Image img = read_png(dir / "cube.png");
  ASSERT_EQ(img.width, 480);
  ASSERT_EQ(img.height, 360);
  const int scene_pixels = static_cast<int>(kSceneFraction * img.width) * img.height;
  const int background = img.count(kBackground, 3, kSceneFraction);
  // Spheres cover a good part of the scene, but not all of it.
  EXPECT_GT(scene_pixels - background, scene_pixels / 5) << "almost blank";
  EXPECT_GT(background, scene_pixels / 10);
  // Small (blue) and large (red) spheres are both drawn, in the scene, not only in the colour bar.
  EXPECT_GT(img.count(kLow, 30, kSceneFraction), 30);
  EXPECT_GT(img.count(kHigh, 30, kSceneFraction), 30);
}

TEST(BasaltView, SkippingBuriedParticlesChangesAlmostNoPixel) {
  const fs::path dir = basalt::test::scratch_dir("view-render-cull");
  const fs::path geo = basalt::test::reference_dir() / "cube1.geo";
  const std::string opts = "--color radius --cut z --size 480x360";
  const Outcome fast =
      basalt_view(fmt_args("render", geo.string(), "-o", (dir / "fast.png").string(), opts), dir);
  const Outcome all =
      basalt_view(fmt_args("render", geo.string(), "-o", (dir / "all.png").string(), opts + " --all"), dir);
  ASSERT_EQ(fast.code, 0) << fast.out;
  ASSERT_EQ(all.code, 0) << all.out;
  EXPECT_NE(fast.out, all.out);  // fewer particles drawn
  const Image a = read_png(dir / "fast.png"), b = read_png(dir / "all.png");
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  int differ = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      if (std::abs(a.pixels[i][c] - b.pixels[i][c]) > 2) {
        ++differ;
        break;
      }
  EXPECT_LT(differ, static_cast<int>(a.pixels.size() / 1000)) << "more than 0.1 % of the pixels differ";
}

TEST(BasaltView, RendersACheckpointFrameBySpeedWithClock) {
  const fs::path dir = basalt::test::scratch_dir("view-render-vtp");
  basalt::io::write_vtp(lattice_checkpoint(), dir / "frame.vtp");
  const Outcome r = basalt_view(fmt_args("render", (dir / "frame.vtp").string(), "-o",
                                         (dir / "speed.png").string(), "--size 400x300 --view -y"),
                                dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("coloured by speed"), std::string::npos)
      << r.out;  // the default field of a checkpoint
  const Image img = read_png(dir / "speed.png");
  ASSERT_EQ(img.width, 400);
  ASSERT_EQ(img.height, 300);
  // Seen from -y, the bottom layer (at rest) is blue and the top layer (fastest) red.
  EXPECT_GT(img.count(kLow, 30, kSceneFraction), 30);
  EXPECT_GT(img.count(kHigh, 30, kSceneFraction), 30);

  // A range above every speed paints everything in the low colour: no red left in the scene.
  const Outcome low =
      basalt_view(fmt_args("render", (dir / "frame.vtp").string(), "-o", (dir / "low.png").string(),
                           "--size 400x300 --view -y --range 1:2"),
                  dir);
  ASSERT_EQ(low.code, 0) << low.out;
  const Image all_low = read_png(dir / "low.png");
  EXPECT_EQ(all_low.count(kHigh, 30, kSceneFraction), 0);
  EXPECT_GT(all_low.count(kLow, 30, kSceneFraction), 300);
}

TEST(BasaltView, RenderErrorsAreClearAndNonZero) {
  const fs::path dir = basalt::test::scratch_dir("view-render-errors");
  const fs::path geo = basalt::test::reference_dir() / "cube1.geo";

  Outcome r =
      basalt_view(fmt_args("render", geo.string(), "-o", (dir / "x.png").string(), "--color speed"), dir);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("unknown colour field \"speed\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("available: id, radius, tag"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "x.png"));

  r = basalt_view(fmt_args("render", (dir / "missing.geo").string(), "-o", (dir / "x.png").string()), dir);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("missing.geo: no such file"), std::string::npos) << r.out;

  r = basalt_view(fmt_args("render", geo.string(), "-o", (dir / "no-such-folder" / "x.png").string()), dir);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("no-such-folder does not exist"), std::string::npos) << r.out;

  r = basalt_view(fmt_args("render", geo.string(), "-o", (dir / "x.png").string(), "--size 100"), dir);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("--size"), std::string::npos) << r.out;
}

TEST(BasaltView, ConvertsGeometryToVtpWithExactPositions) {
  const fs::path dir = basalt::test::scratch_dir("view-convert");
  const fs::path geo = basalt::test::reference_dir() / "cube1.geo";
  const Outcome r = basalt_view(fmt_args("convert", geo.string(), "-o", (dir / "cube.vtp").string()), dir);
  ASSERT_EQ(r.code, 0) << r.out;
  const basalt::io::Geometry g = basalt::io::read_geometry(geo);
  auto pd = read_vtp(dir / "cube.vtp");
  ASSERT_EQ(pd->GetNumberOfPoints(), static_cast<vtkIdType>(g.size()));
  vtkDataArray* radius = pd->GetPointData()->GetArray("radius");
  vtkDataArray* id = pd->GetPointData()->GetArray("id");
  ASSERT_TRUE(radius && id);
  int mismatches = 0;
  for (vtkIdType i = 0; i < pd->GetNumberOfPoints(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    double p[3];
    pd->GetPoint(i, p);
    if (p[0] != g.position[k][0] || p[1] != g.position[k][1] || p[2] != g.position[k][2] ||
        radius->GetTuple1(i) != g.radius[k] || static_cast<std::int64_t>(id->GetTuple1(i)) != g.id[k])
      ++mismatches;
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(BasaltView, ConvertsManyInputsToAPvdSeries) {
  const fs::path dir = basalt::test::scratch_dir("view-convert-series");
  basalt::io::Geometry a;
  for (int i = 0; i < 20; ++i) a.add_particle(i, {0.5 * i, 0.25, 1.0 / 7.0}, 0.2 + 0.01 * i);
  a.box_max = {10, 1, 1};
  basalt::io::Geometry b = a;
  for (auto& p : b.position) p[2] += 0.125;
  basalt::io::write_geo(a, dir / "a.geo");
  basalt::io::write_geo(b, dir / "b.geo");

  Outcome r = basalt_view(fmt_args("convert", (dir / "a.geo").string(), (dir / "b.geo").string(), "-o",
                                   (dir / "series.pvd").string()),
                          dir);
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(dir / "series.pvd");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("file=\"series/a.vtp\""), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("file=\"series/b.vtp\""), std::string::npos) << text.str();
  auto pd = read_vtp(dir / "series" / "b.vtp");
  ASSERT_EQ(pd->GetNumberOfPoints(), 20);
  const basalt::io::Geometry b_read = basalt::io::read_geometry(dir / "b.geo");
  for (vtkIdType i = 0; i < 20; ++i)
    EXPECT_EQ(pd->GetPoint(i)[2], b_read.position[static_cast<std::size_t>(i)][2]);

  // A missing input is found before anything is written.
  r = basalt_view(fmt_args("convert", (dir / "a.geo").string(), (dir / "nope.geo").string(), "-o",
                           (dir / "other.pvd").string()),
                  dir);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("nope.geo: no such file"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "other"));
  EXPECT_FALSE(fs::exists(dir / "other.pvd"));

  // An output folder that does not exist.
  r = basalt_view(fmt_args("convert", (dir / "a.geo").string(), "-o", (dir / "missing" / "a.vtp").string()),
                  dir);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("does not exist"), std::string::npos) << r.out;

  // Several inputs cannot go to one .vtp.
  r = basalt_view(fmt_args("convert", (dir / "a.geo").string(), (dir / "b.geo").string(), "-o",
                           (dir / "one.vtp").string()),
                  dir);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find(".pvd"), std::string::npos) << r.out;
}

TEST(BasaltView, PlotsAValidSeriesAndNamesTheMalformedLine) {
  const fs::path dir = basalt::test::scratch_dir("view-plot");
  {
    std::ofstream csv(dir / "fields.csv");
    csv << "step,time,kinetic_energy\n";
    for (int s = 0; s <= 200; ++s)
      csv << s << "," << s * 1e-3 << "," << std::sin(s * 0.05) * std::sin(s * 0.05) << "\n";
  }
  Outcome r = basalt_view(
      fmt_args("plot", (dir / "fields.csv").string(), "-o", (dir / "ekin.png").string(), "--size 640x400"),
      dir);
  ASSERT_EQ(r.code, 0) << r.out;
  const Image img = read_png(dir / "ekin.png");
  ASSERT_EQ(img.width, 640);
  ASSERT_EQ(img.height, 400);
  const int white = img.count({255, 255, 255}, 2);
  EXPECT_LT(white, img.width * img.height * 98 / 100) << "blank chart";
  EXPECT_GT(img.count({31, 119, 180}, 40), 200) << "no line in the series' colour";

  {
    std::ofstream bad(dir / "bad.csv");
    bad << "step,time,kinetic_energy\n0,0,0\n1,0.001,1e-3,5\n";
  }
  r = basalt_view(fmt_args("plot", (dir / "bad.csv").string(), "-o", (dir / "bad.png").string()), dir);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("bad.csv: line 3"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "bad.png"));

  r = basalt_view(fmt_args("plot", (dir / "fields.csv").string(), "-o", (dir / "x.png").string(),
                           "--columns potential_energy"),
                  dir);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("available: kinetic_energy"), std::string::npos) << r.out;
}

TEST(BasaltView, RendersAnHdf5CheckpointAndAnHdf5Geometry) {
  const fs::path dir = basalt::test::scratch_dir("view-render-h5");
  const basalt::io::Checkpoint c = lattice_checkpoint();
  basalt::io::write_checkpoint(c, dir / "ckpt_00003400.h5");
  basalt::io::write_geometry(c.geometry, dir / "geometry.h5");

  Outcome r = basalt_view(fmt_args("render", (dir / "ckpt_00003400.h5").string(), "-o",
                                   (dir / "ckpt.png").string(), "--size 400x300 --view +x"),
                          dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("coloured by speed"), std::string::npos) << r.out;
  const Image img = read_png(dir / "ckpt.png");
  ASSERT_EQ(img.width, 400);
  EXPECT_GT(img.count(kLow, 30, kSceneFraction), 30);
  EXPECT_GT(img.count(kHigh, 30, kSceneFraction), 30);

  // A geometry .h5 has no velocities: radius by default; all radii equal, so one colour (the middle).
  r = basalt_view(
      fmt_args("render", (dir / "geometry.h5").string(), "-o", (dir / "geo.png").string(), "--size 400x300"),
      dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("coloured by radius"), std::string::npos) << r.out;

  // Displacement from a reference: the lattice moved by (0, 0, 0.25) has displacement 0.25 everywhere.
  basalt::io::Checkpoint moved = c;
  for (auto& p : moved.geometry.position) p[2] += 0.25;
  basalt::io::write_checkpoint(moved, dir / "moved.h5");
  r = basalt_view(fmt_args("convert", (dir / "moved.h5").string(), "-o", (dir / "moved.vtp").string(),
                           "--reference", (dir / "geometry.h5").string()),
                  dir);
  ASSERT_EQ(r.code, 0) << r.out;
  auto pd = read_vtp(dir / "moved.vtp");
  vtkDataArray* d = pd->GetPointData()->GetArray("displacement");
  ASSERT_NE(d, nullptr);
  for (vtkIdType i = 0; i < pd->GetNumberOfPoints(); i += 97) {
    EXPECT_EQ(d->GetComponent(i, 0), 0.0);
    EXPECT_EQ(d->GetComponent(i, 2), (c.geometry.position[static_cast<std::size_t>(i)][2] + 0.25) -
                                         c.geometry.position[static_cast<std::size_t>(i)][2]);
  }
}

TEST(BasaltView, ConvertsCheckpointsToASeriesInTimeOrder) {
  const fs::path dir = basalt::test::scratch_dir("view-convert-ckpt");
  basalt::io::Checkpoint c = lattice_checkpoint();
  c.step = 200;
  c.time = 0.2;
  basalt::io::write_checkpoint(c, dir / "ckpt_00000200.h5");
  c.step = 100;
  c.time = 0.1;
  for (auto& v : c.velocity) v[0] = 0.5;
  basalt::io::write_checkpoint(c, dir / "ckpt_00000100.h5");

  const Outcome r =
      basalt_view(fmt_args("convert", (dir / "ckpt_00000200.h5").string(),
                           (dir / "ckpt_00000100.h5").string(), "-o", (dir / "run.pvd").string()),
                  dir);
  ASSERT_EQ(r.code, 0) << r.out;
  basalt::io::PvdSeries series(dir / "run.pvd", true);
  ASSERT_EQ(series.entries().size(), 2u);
  EXPECT_EQ(series.entries()[0].time, 0.1);
  EXPECT_EQ(series.entries()[0].file, "run/ckpt_00000100.vtp");
  EXPECT_EQ(series.entries()[1].time, 0.2);
  auto pd = read_vtp(dir / "run" / "ckpt_00000100.vtp");
  vtkDataArray* v = pd->GetPointData()->GetArray("velocity");
  ASSERT_NE(v, nullptr);
  for (vtkIdType i = 0; i < pd->GetNumberOfPoints(); ++i) {
    EXPECT_EQ(v->GetComponent(i, 0), 0.5);
    EXPECT_EQ(v->GetComponent(i, 2), c.velocity[static_cast<std::size_t>(i)][2]);
  }
}

TEST(BasaltView, RendersAParallelFrameAndReportsItsFields) {
  const fs::path dir = basalt::test::scratch_dir("view-pvtp");
  // The lattice split in two pieces, as two I/O ranks write it.
  const basalt::io::Checkpoint c = lattice_checkpoint();
  const auto all = basalt::io::arrays_of(c);
  const std::size_t half = c.size() / 2;
  basalt::io::ParticleArrays lo = all, hi = all;
  lo.id = all.id.subspan(0, half);
  lo.position = all.position.subspan(0, half);
  lo.radius = all.radius.subspan(0, half);
  lo.tag = all.tag.subspan(0, half);
  lo.velocity = all.velocity.subspan(0, half);
  lo.mass = all.mass.subspan(0, half);
  hi.id = all.id.subspan(half);
  hi.position = all.position.subspan(half);
  hi.radius = all.radius.subspan(half);
  hi.tag = all.tag.subspan(half);
  hi.velocity = all.velocity.subspan(half);
  hi.mass = all.mass.subspan(half);
  const auto layout = basalt::io::layout_of(all);
  basalt::io::write_piece(dir, c.step, 0, 2, lo, basalt::io::info_of(c), layout);
  basalt::io::write_piece(dir, c.step, 1, 2, hi, basalt::io::info_of(c), layout);
  const fs::path pvtp = basalt::io::write_pvtp(dir, c.step, 2, layout);

  Outcome r = basalt_view(fmt_args("info", pvtp.string()), dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("1728 particles"), std::string::npos) << r.out;
  EXPECT_NE(
      r.out.find("colour fields: id, radius, tag, mass, velocity, velocity_x, velocity_y, velocity_z, speed"),
      std::string::npos)
      << r.out;

  r = basalt_view(fmt_args("render", pvtp.string(), "-o", (dir / "p.png").string(),
                           "--size 400x300 --view -y --color velocity_z"),
                  dir);
  ASSERT_EQ(r.code, 0) << r.out;
  const Image img = read_png(dir / "p.png");
  EXPECT_GT(img.count(kLow, 30, kSceneFraction), 30);   // bottom half (piece 0) at rest
  EXPECT_GT(img.count(kHigh, 30, kSceneFraction), 30);  // top half (piece 1) fastest
}

TEST(BasaltView, StartsItsOwnXServerAlsoForConcurrentCommands) {
  const fs::path dir = basalt::test::scratch_dir("view-xvfb");
  const fs::path geo = basalt::test::reference_dir() / "cube1.geo";
  // Three renders at once, each starting its own Xvfb: the servers pick distinct free displays.
  std::string cmd = "env -u DISPLAY sh -c '";
  for (int i = 0; i < 3; ++i)
    cmd += fmt::format("\"{}\" render \"{}\" -o \"{}\" --size 200x150 -q & ", BASALT_VIEW_EXE, geo.string(),
                       (dir / fmt::format("c{}.png", i)).string());
  cmd += "wait'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  for (int i = 0; i < 3; ++i) {
    const Image img = read_png(dir / fmt::format("c{}.png", i));
    EXPECT_EQ(img.width, 200) << i;
    EXPECT_EQ(img.height, 150) << i;
  }

  // Without Xvfb on the PATH, a clear error instead of VTK's.
  const Outcome r =
      basalt_view(fmt_args("render", geo.string(), "-o", (dir / "x.png").string()), dir, "PATH=/nonexistent");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("Xvfb is not installed"), std::string::npos) << r.out;
}

// ---- issue 16: plots that drew nothing, renders far from the origin (docs/reliability.md) ------------

TEST(BasaltView, PlotsTheFinitePointsAndSaysWhatWasLeftOut) {
  const fs::path dir = basalt::test::scratch_dir("view-plot-nonfinite");
  const Rgb kLine{31, 119, 180};
  {
    std::ofstream csv(dir / "inf.csv");  // an empty chart, exit 0
    csv << "step,time,kinetic_energy\n";
    for (int s = 0; s <= 100; ++s)
      csv << s << "," << s * 1e-3 << ","
          << (s % 25 == 7 ? "inf"
              : s == 50   ? "nan"
                          : std::to_string(s * s))
          << "\n";
  }
  Outcome r = basalt_view(
      fmt_args("plot", (dir / "inf.csv").string(), "-o", (dir / "inf.png").string(), "--size 400x300"), dir);
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* w :
       {"inf.csv: column \"kinetic_energy\": 5 of 101 rows not drawn", "line 9: inf", "(5 in all)"})
    EXPECT_NE(r.out.find(w), std::string::npos) << w << " missing from: " << r.out;
  EXPECT_GT(read_png(dir / "inf.png").count(kLine, 40), 150) << "no line drawn";

  // +-1e308: the axis was 2e308 long (infinite), and VTK draws in single precision.
  {
    std::ofstream csv(dir / "big.csv");
    csv << "step,time,kinetic_energy\n";
    for (int s = 0; s <= 40; ++s) csv << s << "," << s << "," << (s % 2 ? "-1e308" : "1e308") << "\n";
  }
  r = basalt_view(
      fmt_args("plot", (dir / "big.csv").string(), "-o", (dir / "big.png").string(), "--size 400x300"), dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_GT(read_png(dir / "big.png").count(kLine, 40), 500) << "no line drawn";
  {
    std::ofstream csv(dir / "tiny.csv");
    csv << "step,time,kinetic_energy\n0,0,1e-310\n1,1e-40,3e-310\n2,2e-40,2e-310\n";
  }
  r = basalt_view(
      fmt_args("plot", (dir / "tiny.csv").string(), "-o", (dir / "tiny.png").string(), "--size 400x300"),
      dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_GT(read_png(dir / "tiny.png").count(kLine, 40), 150) << "no line drawn";

  // One row: a line needs two points; the lone one is a marker (the axes get a length).
  {
    std::ofstream csv(dir / "one.csv");
    csv << "step,time,kinetic_energy\n100,0.1,2.5\n";
  }
  r = basalt_view(
      fmt_args("plot", (dir / "one.csv").string(), "-o", (dir / "one.png").string(), "--size 400x300"), dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("ERR"), std::string::npos) << r.out;
  EXPECT_GT(read_png(dir / "one.png").count(kLine, 40), 20) << "no point drawn";
}

TEST(BasaltView, RefusesAChartWithNothingToDraw) {
  const fs::path dir = basalt::test::scratch_dir("view-plot-nothing");
  {
    std::ofstream csv(dir / "none.csv");
    csv << "step,time,kinetic_energy,wall_force\n0,0,inf,\n1,0.001,nan,\n2,inf,1,\n";
  }
  Outcome r =
      basalt_view(fmt_args("plot", (dir / "none.csv").string(), "-o", (dir / "none.png").string()), dir);
  EXPECT_EQ(r.code, 1) << r.out;
  for (const char* w : {"basalt-view: error: ", "none.csv: column \"kinetic_energy\": nothing to draw",
                        "line 2: inf", "line 4: time inf", "column \"wall_force\": nothing to draw",
                        "saver was never due", "no chart written"})
    EXPECT_NE(r.out.find(w), std::string::npos) << w << " missing from: " << r.out;
  EXPECT_FALSE(fs::exists(dir / "none.png"));
  r = basalt_view(fmt_args("plot", (dir / "none.csv").string(), "-o", (dir / "some.png").string(),
                           "--columns kinetic_energy,wall_force"),
                  dir);
  EXPECT_EQ(r.code, 1) << r.out;  // the same columns named: still nothing to draw
  EXPECT_NE(r.out.find("nothing to draw"), std::string::npos) << r.out;
  // One column with nothing beside one with points: drawn, the empty one named.
  {
    std::ofstream csv(dir / "half.csv");
    csv << "step,time,kinetic_energy,wall_force\n0,0,1,inf\n1,0.001,2,nan\n2,0.002,1.5,inf\n";
  }
  r = basalt_view(fmt_args("plot", (dir / "half.csv").string(), "-o", (dir / "half.png").string()), dir);
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("column \"wall_force\": nothing to draw"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("left out of the chart"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir / "half.png"));
}

TEST(BasaltView, RendersParticlesFarFromTheOrigin) {
  // Positions 1e9 from the origin rendered blank (single-precision OpenGL); now drawn relative to the
  // frame's centre.
  for (double offset : {1e9, 1e12}) {
    const fs::path dir = basalt::test::scratch_dir(fmt::format("view-render-offset-{:g}", offset));
    basalt::io::Checkpoint c = lattice_checkpoint();
    for (auto& p : c.geometry.position) p = {p[0] + offset, p[1] - offset, p[2] + offset};
    basalt::io::write_checkpoint(c, dir / "ckpt.h5");
    const Outcome r = basalt_view(fmt_args("render", (dir / "ckpt.h5").string(), "-o",
                                           (dir / "far.png").string(), "--size 400x300 --view -y"),
                                  dir);
    ASSERT_EQ(r.code, 0) << r.out;
    const Image img = read_png(dir / "far.png");
    ASSERT_EQ(img.width, 400);
    const int scene_pixels = static_cast<int>(kSceneFraction * img.width) * img.height;
    EXPECT_GT(scene_pixels - img.count(kBackground, 3, kSceneFraction), scene_pixels / 5)
        << "almost blank at offset " << offset;
    EXPECT_GT(img.count(kLow, 30, kSceneFraction), 30) << offset;
    EXPECT_GT(img.count(kHigh, 30, kSceneFraction), 30) << offset;
  }
}

// ---- issue 15: robust colour range, strips of panels, series and movies --------------------------------

namespace {

/// The lattice with `fast` particles on its -y face (seen from -y) far faster than the rest: the
/// free-surface outliers that squeezed the demo's wave into one shade of blue.
basalt::io::Checkpoint lattice_with_outliers(int fast) {
  basalt::io::Checkpoint c = lattice_checkpoint();
  for (int i = 0; i < fast; ++i) c.velocity[static_cast<std::size_t>(6 * 144 + i)][2] = 10.0;
  return c;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(BasaltView, DefaultRangeIsThePercentilesSoOutliersDoNotSqueezeTheMap) {
  const fs::path dir = basalt::test::scratch_dir("view-robust-range");
  basalt::io::write_checkpoint(lattice_with_outliers(6), dir / "ckpt_000400.h5");
  const std::string in = (dir / "ckpt_000400.h5").string();
  Outcome r = basalt_view(fmt_args("render", in, "-o", (dir / "robust.png").string(),
                                   "--size 400x300 --view -y --color velocity_z"),
                          dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("p1-p99, clamped"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("values from 0 to 10"), std::string::npos) << r.out;  // the true extremes
  const Image robust = read_png(dir / "robust.png");
  // The bulk spans the map: low layers blue, high layers red, many of each.
  EXPECT_GT(robust.count(kLow, 30, kSceneFraction), 300);
  EXPECT_GT(robust.count(kHigh, 30, kSceneFraction), 300);

  // The old default, the full range 0..10, paints the whole bulk blue: only the outliers are red.
  r = basalt_view(fmt_args("render", in, "-o", (dir / "full.png").string(),
                           "--size 400x300 --view -y --color velocity_z --range 0:10"),
                  dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("--range, clamped"), std::string::npos) << r.out;
  const Image full = read_png(dir / "full.png");
  EXPECT_GT(full.count(kLow, 30, kSceneFraction), 3 * robust.count(kLow, 30, kSceneFraction));
}

TEST(BasaltView, SeveralFilesToOnePngMakeAStripOfPanelsWithOneRange) {
  const fs::path dir = basalt::test::scratch_dir("view-strip");
  // Four frames of a wave: at step s the layers below height s/100 move, the others are at rest.
  std::vector<std::string> args{"render"};
  for (int s = 1; s <= 4; ++s) {
    basalt::io::Checkpoint c = lattice_checkpoint();
    c.step = 200 * s;
    c.time = 0.2 * s;
    for (std::size_t i = 0; i < c.size(); ++i)
      c.velocity[i][2] = c.geometry.position[i][2] < 3 * s ? 0.1 : 0.0;
    const fs::path f = dir / fmt::format("ckpt_{:06d}.h5", c.step);
    basalt::io::write_checkpoint(c, f);
    args.push_back(f.string());
  }
  std::string cmd;
  for (const auto& a : args) cmd += "'" + a + "' ";
  const Outcome r =
      basalt_view(cmd + fmt_args("-o", (dir / "strip.png").string(), "--view -y --color velocity_z"), dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("4 panels"), std::string::npos) << r.out;
  const Image img = read_png(dir / "strip.png");
  ASSERT_EQ(img.width, 4 * 560 + 180);  // the default: 560x600 per panel and the colour bar
  ASSERT_EQ(img.height, 600);
  const double panel = 560.0 / img.width;
  int previous_red = 0;
  for (int i = 0; i < 4; ++i) {
    const int red = img.count_between(kHigh, 30, i * panel, (i + 1) * panel);
    const int blue = img.count_between(kLow, 30, i * panel, (i + 1) * panel);
    // One range for all: the moving part grows from panel to panel, in the same red.
    EXPECT_GT(red, previous_red + 1000) << "panel " << i;
    if (i < 3) {
      EXPECT_GT(blue, 1000) << "panel " << i;
    }
    previous_red = red;
  }
}

TEST(BasaltView, RendersASeriesIntoAFolderWithOneRange) {
  const fs::path dir = basalt::test::scratch_dir("view-series");
  basalt::io::Checkpoint c = lattice_checkpoint();  // velocity_z 0 .. 0.11 with height
  basalt::io::write_checkpoint(c, dir / "ckpt_000100.h5");
  c.step = 200;
  for (auto& v : c.velocity) v[2] *= 0.4;  // slower: alone, its top would be red too
  basalt::io::write_checkpoint(c, dir / "ckpt_000200.h5");
  c.step = 300;
  basalt::io::write_checkpoint(c, dir / "ckpt_000300.h5");
  const Outcome r = basalt_view(fmt_args("render", (dir / "ckpt_000100.h5").string(),
                                         (dir / "ckpt_000200.h5").string(), (dir / "ckpt_000300.h5").string(),
                                         "-o", (dir / "frames/").string(), "--size 400x300 --view -y"),
                                dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("wrote 3 pictures"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("[3/3]"), std::string::npos) << r.out;  // the progress line
  std::vector<fs::path> pngs;
  for (const auto& e : fs::directory_iterator(dir / "frames")) pngs.push_back(e.path());
  ASSERT_EQ(pngs.size(), 3u);
  const Image fast = read_png(dir / "frames" / "ckpt_000100.png");
  const Image slow = read_png(dir / "frames" / "ckpt_000200.png");
  ASSERT_EQ(fast.width, 400);
  ASSERT_EQ(slow.width, 400);
  EXPECT_GT(fast.count(kHigh, 30, kSceneFraction), 300);
  EXPECT_GT(fast.count(kLow, 30, kSceneFraction), 300);
  EXPECT_EQ(slow.count(kHigh, 30, kSceneFraction), 0);  // same colours mean the same speeds
  EXPECT_GT(slow.count(kLow, 30, kSceneFraction), 300);
}

TEST(BasaltView, MovieOfARunFolderIsAnAnimatedPngWithOneFramePerCheckpoint) {
  const fs::path dir = basalt::test::scratch_dir("view-movie");
  fs::create_directories(dir / "run");
  basalt::io::Checkpoint c = lattice_checkpoint();
  for (int s = 1; s <= 5; ++s) {
    c.step = 100 * s;
    c.time = 0.1 * s;
    basalt::io::write_checkpoint(c, dir / "run" / fmt::format("ckpt_{:06d}.h5", c.step));
  }
  std::ofstream(dir / "run" / "ckpt_000600.h5.partial") << "half-written";
  const Outcome r = basalt_view(
      fmt_args("movie", (dir / "run").string(), "-o", (dir / "run.png").string(), "--size 320x240 --view -y"),
      dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("5 frames"), std::string::npos) << r.out;
  const std::string png = read_text(dir / "run.png");
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  // The chunks: acTL announces 5 frames, and there are 5 frame controls (fcTL).
  int fctl = 0, frames = -1;
  for (std::size_t at = 8; at + 12 <= png.size();) {
    const auto byte = [&](std::size_t i) {
      return static_cast<std::uint32_t>(static_cast<unsigned char>(png[i]));
    };
    const std::uint32_t len = (byte(at) << 24) | (byte(at + 1) << 16) | (byte(at + 2) << 8) | byte(at + 3);
    const std::string type = png.substr(at + 4, 4);
    if (type == "acTL") frames = static_cast<int>(byte(at + 11));
    if (type == "fcTL") ++fctl;
    at += 12 + len;
  }
  EXPECT_EQ(frames, 5);
  EXPECT_EQ(fctl, 5);
  // Any PNG reader sees the first frame: the right size, not blank, both ends of the map.
  const Image first = read_png(dir / "run.png");
  ASSERT_EQ(first.width, 320);
  ASSERT_EQ(first.height, 240);
  EXPECT_GT(first.count(kLow, 30, kSceneFraction), 30);
  EXPECT_GT(first.count(kHigh, 30, kSceneFraction), 30);

  const Outcome bad = basalt_view(fmt_args("movie", dir.string(), "-o", (dir / "x.png").string()), dir);
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.out.find("no checkpoints"), std::string::npos) << bad.out;
}

TEST(BasaltView, ColoursACheckpointByItsParticleFieldsSuchAsAngularVelocity) {
  // A checkpoint of a rotating scene stores angular_velocity_x/_y/_z as particle fields (column-collapse's
  // rot_friction): each component, and the magnitude under the common name, colour the spheres. The
  // lattice spins faster with x (and the other way in y, so the magnitude is not one component).
  const fs::path dir = basalt::test::scratch_dir("view-render-fields");
  basalt::io::Checkpoint c = lattice_checkpoint();
  std::vector<double> wx, wy, wz;
  for (const auto& p : c.geometry.position) {
    wx.push_back(0.0);
    wy.push_back(-0.5 * p[0]);
    wz.push_back(p[0]);
  }
  c.particle_fields = {{"angular_velocity_x", wx}, {"angular_velocity_y", wy}, {"angular_velocity_z", wz}};
  basalt::io::write_checkpoint(c, dir / "ckpt_000100.h5");

  Outcome r = basalt_view(fmt_args("info", (dir / "ckpt_000100.h5").string()), dir);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("angular_velocity_x, angular_velocity_y, angular_velocity_z"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find(", angular_velocity\n"), std::string::npos) << r.out;  // the magnitude

  for (const std::string field : {"angular_velocity", "angular_velocity_z"}) {
    const fs::path png = dir / (field + ".png");
    r = basalt_view(fmt_args("render", (dir / "ckpt_000100.h5").string(), "-o", png.string(),
                             "--size 400x300 --view -y --color " + field),
                    dir);
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("coloured by " + field + ","), std::string::npos) << r.out;
    // |omega| = 1.118 x, omega_z = x: from 0 at x = 0 to the top of the map at x = 11.
    EXPECT_NE(r.out.find("values from 0 to " + std::string(field == "angular_velocity" ? "12.2" : "11")),
              std::string::npos)
        << r.out;
    const Image img = read_png(png);
    ASSERT_EQ(img.width, 400);
    // Seen from -y, x runs left to right: blue on the left, red on the right, both in the scene.
    EXPECT_GT(img.count_between(kLow, 30, 0.0, 0.4), 30) << field;
    EXPECT_GT(img.count_between(kHigh, 30, 0.4, kSceneFraction), 30) << field;
    EXPECT_EQ(img.count_between(kHigh, 30, 0.0, 0.3), 0) << field;
  }
}

namespace {

/// Pixels of the crack colour (yellow, lit or shaded: red and green high, blue low), which no colour of the
/// cool-to-warm map nor the background comes near, with x0_fraction * width <= x < x1_fraction * width.
int crack_pixels(const Image& img, double x0_fraction = 0.0, double x1_fraction = 1.0) {
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = static_cast<int>(x0_fraction * img.width); x < static_cast<int>(x1_fraction * img.width);
         ++x) {
      const Rgb& p = img.pixels[static_cast<std::size_t>(y * img.width + x)];
      if (p[0] > 150 && p[1] > 120 && p[2] < 60 && p[1] < p[0]) ++n;
    }
  return n;
}

/// The 12x12x12 lattice with bonds between x-neighbours; those between x = 5 and x = 6 (144) broken.
/// `where`: the recorded break positions' x (none recorded when NaN).
basalt::io::Checkpoint cracked_lattice(bool broken, double where) {
  basalt::io::Checkpoint c = lattice_checkpoint();
  for (int k = 0; k < 12; ++k)
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i + 1 < 12; ++i) {
        const std::int64_t a = k * 144 + j * 12 + i;
        c.geometry.bonds.push_back({a, a + 1, 0});
        c.bond_rest_length.push_back(1.0);
        const bool cracked = broken && i == 5;
        c.bond_broken.push_back(cracked ? std::uint8_t(1 | (1 << 2)) : std::uint8_t(0));
        if (cracked && !std::isnan(where)) c.bond_break_position.push_back({where, 1.0 * j, 1.0 * k});
      }
  return c;
}

}  // namespace

TEST(BasaltView, DrawsBrokenBondsWhereTheyBrokeInTheirOwnColour) {
  // Seen from -y, x runs left to right across the scene (the left 84 % of the image, centre at 0.42); the
  // 12 broken bonds along y behind each other show as one point each.
  const fs::path dir = basalt::test::scratch_dir("view-render-cracks");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  basalt::io::write_checkpoint(cracked_lattice(true, 5.5), dir / "ckpt_000100.h5");   // broke in the middle
  basalt::io::write_checkpoint(cracked_lattice(true, 1.5), dir / "ckpt_000200.h5");   // recorded near x = 1.5
  basalt::io::write_checkpoint(cracked_lattice(true, nan), dir / "ckpt_000300.h5");   // not recorded
  basalt::io::write_checkpoint(cracked_lattice(false, nan), dir / "ckpt_000400.h5");  // bonds, none broken
  const auto render = [&](const std::string& file, const std::string& options) {
    return basalt_view(fmt_args("render", (dir / file).string(), "-o", (dir / "out.png").string(),
                                "--size 400x300 --view -y " + options),
                       dir);
  };

  // Default: drawn, since the checkpoint has broken bonds; all of them in a vertical band at x = 5.5.
  Outcome r = render("ckpt_000100.h5", "");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("; 144 broken bonds, 144 drawn;"), std::string::npos) << r.out;
  Image img = read_png(dir / "out.png");
  ASSERT_EQ(img.width, 400);
  EXPECT_GT(crack_pixels(img, 0.36, 0.48), 40);
  EXPECT_EQ(crack_pixels(img, 0.0, 0.36) + crack_pixels(img, 0.48, 1.0), 0);
  EXPECT_GT(img.count(kLow, 30, kSceneFraction), 100);  // the particles are still drawn

  // The recorded position, not the ends' present contact point (x = 5.5), places them.
  r = render("ckpt_000200.h5", "");
  ASSERT_EQ(r.code, 0) << r.out;
  img = read_png(dir / "out.png");
  EXPECT_GT(crack_pixels(img, 0.0, 0.3), 40);
  EXPECT_EQ(crack_pixels(img, 0.3, 1.0), 0);
  // Without a record: at the ends' contact point now, and said so.
  r = render("ckpt_000300.h5", "");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("144 without a recorded break position"), std::string::npos) << r.out;
  img = read_png(dir / "out.png");
  EXPECT_GT(crack_pixels(img, 0.36, 0.48), 40);
  EXPECT_EQ(crack_pixels(img, 0.0, 0.36) + crack_pixels(img, 0.48, 1.0), 0);

  // The cut keeps the half behind it (y >= 5.5 seen from -y): 72 of the 144.
  r = render("ckpt_000100.h5", "--cut y");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("; 144 broken bonds, 72 drawn;"), std::string::npos) << r.out;
  EXPECT_GT(crack_pixels(read_png(dir / "out.png"), 0.36, 0.48), 40);

  // Off on request, and nothing to draw without broken bonds: no crack colour, no count.
  for (const auto& [file, option] : {std::pair{"ckpt_000100.h5", "--no-cracks"}, {"ckpt_000400.h5", ""}}) {
    r = render(file, option);
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(r.out.find("broken bonds"), std::string::npos) << r.out;
    img = read_png(dir / "out.png");
    EXPECT_EQ(crack_pixels(img), 0) << file << " " << option;
    EXPECT_GT(img.count(kLow, 30, kSceneFraction), 100);
  }
  // --cracks on a checkpoint without broken bonds draws none and says 0.
  r = render("ckpt_000400.h5", "--cracks");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("; 0 broken bonds, 0 drawn;"), std::string::npos) << r.out;

  // Only the cracks: no particles (neither end of the map) and no colour bar.
  r = render("ckpt_000100.h5", "--only-cracks --crack-radius 0.3");
  ASSERT_EQ(r.code, 0) << r.out;
  img = read_png(dir / "out.png");
  EXPECT_GT(crack_pixels(img, 0.36, 0.48), 300);
  EXPECT_EQ(img.count(kLow, 30) + img.count(kHigh, 30), 0);
  // ... and the line names no colour range it did not use.
  EXPECT_NE(r.out.find("0 drawn, particles not drawn (--only-cracks); "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("coloured by"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("range "), std::string::npos) << r.out;

  r = render("ckpt_000100.h5", "--crack-radius -1");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("--crack-radius"), std::string::npos) << r.out;
  r = render("ckpt_000100.h5", "--cracks --no-cracks");
  EXPECT_NE(r.code, 0);
}
