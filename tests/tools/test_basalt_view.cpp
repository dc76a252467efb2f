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
#include <sstream>

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
