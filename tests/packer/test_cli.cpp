// basalt-pack as a user runs it: the documented command lines, the printed statistics, byte-identical
// output for the same seed, and a clear error with a non-zero exit for each bad input.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "basalt/io/geometry.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;

namespace {

struct Run {
  int status = -1;
  std::string output;  // stdout and stderr
};

Run run(const std::string& args) {
  Run r;
  const std::string cmd = std::string(BASALT_PACK_EXE) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) r.output += buf;
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

bool contains(const std::string& s, const std::string& w) { return s.find(w) != std::string::npos; }

}  // namespace

TEST(Cli, BoxToGeoPrintsStatisticsAndWritesReadableFile) {
  const auto dir = basalt::test::scratch_dir("packer-cli-box");
  const auto out = dir / "cube.geo";
  const auto r = run("box --size 6,6,6 --rmin 0.2 --rmax 1.0 --seed 7 -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* w : {"particles", "solid fraction", "fitted exponent", "radius histogram",
                        "bonds per particle", "mean coordination", "largest overlap", "time"})
    EXPECT_TRUE(contains(r.output, w)) << w << " missing from:\n" << r.output;
  const auto g = basalt::io::read_geometry(out);
  EXPECT_GT(g.size(), 300u);
  EXPECT_GT(g.bonds.size(), g.size());
  for (std::size_t i = 0; i < g.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(g.position[i][k] - g.radius[i], -1e-6);
      EXPECT_LE(g.position[i][k] + g.radius[i], 6 + 1e-6);
    }
  }
}

TEST(Cli, SameSeedSameBytesAndTimeOnlyWhenAsked) {
  const auto dir = basalt::test::scratch_dir("packer-cli-bytes");
  const std::string args = "cylinder --radius 3 --height 4 --rmin 0.2 --rmax 0.8 --seed 5 -q -o ";
  ASSERT_EQ(run(args + (dir / "a.geo").string()).status, 0);
  ASSERT_EQ(run(args + (dir / "b.geo").string()).status, 0);
  const auto a = slurp(dir / "a.geo"), b = slurp(dir / "b.geo");
  EXPECT_FALSE(a.empty());
  EXPECT_TRUE(a == b) << "same seed, different bytes";
  ASSERT_EQ(
      run("cylinder --radius 3 --height 4 --rmin 0.2 --rmax 0.8 --seed 6 -q -o " + (dir / "c.geo").string())
          .status,
      0);
  EXPECT_FALSE(a == slurp(dir / "c.geo")) << "another seed, same bytes";
}

TEST(Cli, HeadlineCommandWritesHdf5WithStatistics) {
  const auto dir = basalt::test::scratch_dir("packer-cli-h5");
  const auto out = dir / "cube.h5";
  const auto r = run("box --size 6,6,6 --rmin 0.2 --rmax 1.0 --seed 7 -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const auto g = basalt::io::read_geometry(out);
  EXPECT_GT(g.size(), 300u);
  EXPECT_EQ(g.statistics.count("solid_fraction"), 1u);
  EXPECT_EQ(g.attributes.count("command_line"), 1u);
  EXPECT_EQ(g.attributes.at("command_line").find("cube.h5"), std::string::npos);
  // Same arguments, another name, another day: the same bytes (no time, no output name inside).
  ASSERT_EQ(
      run("box --size 6,6,6 --rmin 0.2 --rmax 1.0 --seed 7 -q -o " + (dir / "again.h5").string()).status, 0);
  EXPECT_TRUE(slurp(out) == slurp(dir / "again.h5")) << "same arguments, different bytes";
  // --record-time stores the time, and then the bytes differ.
  ASSERT_EQ(
      run("box --size 6,6,6 --rmin 0.2 --rmax 1.0 --seed 7 -q --record-time -o " + (dir / "t.h5").string())
          .status,
      0);
  const auto t = basalt::io::read_geometry(dir / "t.h5");
  EXPECT_EQ(t.statistics.count("pack_seconds"), 1u);
  EXPECT_EQ(t.attributes.count("created"), 1u);
  EXPECT_EQ(g.statistics.count("pack_seconds"), 0u);
}

TEST(Cli, SphereMeshAndPowerLawCommands) {
  const auto dir = basalt::test::scratch_dir("packer-cli-more");
  auto r = run("sphere --radius 3 --rmin 0.2 --rmax 0.8 -q -o " + (dir / "s.geo").string());
  EXPECT_EQ(r.status, 0) << r.output;
  std::ofstream(dir / "cube.off")
      << "OFF\n8 12 0\n0 0 0\n4 0 0\n4 4 0\n0 4 0\n0 0 4\n4 0 4\n4 4 4\n0 4 4\n"
         "3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n3 1 2 6\n3 1 6 5\n"
         "3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n";
  r = run("mesh " + (dir / "cube.off").string() + " --rmin 0.2 --rmax 0.8 -o " + (dir / "m.geo").string());
  EXPECT_EQ(r.status, 0) << r.output;
  r = run(
      "box --size 5,5,5 --rmin 0.1 --rmax 1 --exponent 2 --target-fraction 0.45 --tag-layer zmin:0.5:2 -o " +
      (dir / "p.geo").string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "radii drawn/placed")) << r.output;
  const auto g = basalt::io::read_geometry(dir / "p.geo");
  int tagged = 0;
  for (auto t : g.tag) tagged += t == 2;
  EXPECT_GT(tagged, 10);
}

TEST(Cli, BadInputFailsWithAClearMessage) {
  const auto dir = basalt::test::scratch_dir("packer-cli-bad");
  const std::string o = " -o " + (dir / "x.geo").string();
  struct Case {
    std::string args, words;
  };
  std::ofstream(dir / "open.off") << "OFF\n4 3 0\n0 0 0\n4 0 0\n0 4 0\n0 0 4\n3 0 2 1\n3 0 1 3\n3 0 3 2\n";
  std::ofstream(dir / "plain.txt") << "a file, not a folder\n";
  const Case cases[] = {
      {"box --size 5,5,5 --rmin 1.0 --rmax 0.5" + o, "rmin must not exceed rmax"},
      {"box --size 5,5,5 --rmin 0 --rmax 0.5" + o, "rmin must be > 0"},
      {"box --size 5,5,5 --rmin -1 --rmax 0.5" + o, "rmin must be > 0"},
      {"box --size 0.3,5,5 --rmin 0.2 --rmax 0.5" + o, "too small for one sphere"},
      {"box --size 5,5 --rmin 0.2 --rmax 0.5" + o, "three comma-separated numbers"},
      {"mesh " + (dir / "open.off").string() + " --rmin 0.2 --rmax 0.5" + o, "open"},
      {"box --size 5,5,5 --rmin 0.2 --rmax 0.5 -o /nonexistent-folder/x.geo", "does not exist"},
      {"box --size 5,5,5 --rmin 0.2 --rmax 0.5 -o " + (dir / "plain.txt" / "x.geo").string(), "cannot write"},
      {"box --size 5,5,5 --rmin 0.2 --rmax 0.5 -o " + (dir / "x.vtk").string(), "unknown output format"},
      {"box --size 5,5,5 --rmin 0.2 --rmax 0.5 --tag-layer top:1:2" + o, "no face 'top'"},
      {"box --size 5,5,5 --rmin 0.2 --rmax 0.5 --exponent 0" + o, "exponent must be > 0"},
  };
  for (const auto& c : cases) {
    const auto r = run(c.args);
    EXPECT_NE(r.status, 0) << c.args;
    EXPECT_TRUE(contains(r.output, c.words)) << c.args << "\nprinted:\n" << r.output;
  }
  EXPECT_FALSE(fs::exists(dir / "x.geo"));
  EXPECT_NE(run("box --rmin 0.2 --rmax 0.5" + o).status, 0);  // --size missing: usage error
}

TEST(Cli, AFailedRunKeepsTheFileAlreadyThere) {
  const auto dir = basalt::test::scratch_dir("packer-cli-keep");
  const auto out = dir / "keep.geo";
  ASSERT_EQ(run("box --size 4,4,4 --rmin 0.3 --rmax 1 -q -o " + out.string()).status, 0);
  const auto before = slurp(out);
  EXPECT_NE(run("box --size 4,4,4 --rmin 2 --rmax 1 -q -o " + out.string()).status, 0);
  EXPECT_TRUE(slurp(out) == before) << "a failed run changed the existing file";
}

// ---- issue 16 (docs/reliability.md) ----------------------------------------------------------------

TEST(Cli, SteepExponentsAndHugeVolumesAreRefusedBeforeAnyWork) {
  const auto dir = basalt::test::scratch_dir("packer-cli-absurd");
  const std::string o = " -o " + (dir / "x.h5").string();
  // Exponent 600 segfaulted; 1e4 and 1e308 grew memory until std::bad_alloc.
  for (const char* a : {"600", "500", "800", "1e4", "1e308"}) {
    const auto r = run(std::string("box --size 3,3,3 --rmin 0.2 --rmax 0.5 --exponent ") + a + o);
    EXPECT_EQ(r.status, 1) << a << ": " << r.output;
    EXPECT_TRUE(contains(r.output, "beyond the useful range (0, 20]")) << r.output;
  }
  // --size 1e6,1e6,1e6 grew memory without bound: refused with the estimate and its memory.
  auto r = run("box --size 1e6,1e6,1e6 --rmin 0.2 --rmax 0.5" + o);
  EXPECT_EQ(r.status, 1) << r.output;
  for (const char* w : {"would take about 5.", "e+18 spheres", "EiB of memory", "--allow-large"})
    EXPECT_TRUE(contains(r.output, w)) << w << " missing from: " << r.output;
  r = run("sphere --radius 1e5 --rmin 0.01 --rmax 0.02 --exponent 2" + o);
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "--allow-large")) << r.output;
  EXPECT_FALSE(fs::exists(dir / "x.h5"));
  // The limit is a limit: --allow-large packs beyond it.
  r = run("box --size 6,6,6 --rmin 0.2 --rmax 1 --max-spheres 100 -q" + o);
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "beyond the 100 spheres")) << r.output;
  r = run("box --size 6,6,6 --rmin 0.2 --rmax 1 --max-spheres 100 --allow-large -q" + o);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_GT(basalt::io::read_geometry(dir / "x.h5").size(), 100u);
}

TEST(Cli, SmallVolumesAreFilledOrTheReasonIsGiven) {
  const auto dir = basalt::test::scratch_dir("packer-cli-small");
  // 2 x 2 x 2 with radii up to 0.5 wrote 2 spheres (solid fraction 0.13) and exit 0.
  auto r = run("box --size 2,2,2 --rmin 0.2 --rmax 0.5 -o " + (dir / "a.h5").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_GE(basalt::io::read_geometry(dir / "a.h5").size(), 10u);
  EXPECT_TRUE(contains(r.output, "note: solid fraction")) << r.output;  // the wall layer, said
  r = run("sphere --radius 1.2 --rmin 0.2 --rmax 0.5 -q -o " + (dir / "b.h5").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_GE(basalt::io::read_geometry(dir / "b.h5").size(), 15u);
  // Where nothing more fits, the fraction is far below the mode's: an error that says why, no file ...
  r = run("box --size 1.2,1.2,1.2 --rmin 0.5 --rmax 0.5 -o " + (dir / "c.h5").string());
  EXPECT_EQ(r.status, 1) << r.output;
  for (const char* w : {"far below the dense mode's 0.70", "no room is left", "--allow-low-fraction"})
    EXPECT_TRUE(contains(r.output, w)) << w << " missing from: " << r.output;
  EXPECT_FALSE(fs::exists(dir / "c.h5"));
  // ... unless asked: then a warning, and the file.
  r = run("box --size 1.2,1.2,1.2 --rmin 0.5 --rmax 0.5 --allow-low-fraction -q -o " +
          (dir / "c.h5").string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "warning: solid fraction 0.303")) << r.output;
  EXPECT_EQ(basalt::io::read_geometry(dir / "c.h5").size(), 1u);
}

TEST(Cli, AnUnknownShapeOrANegativeSeedIsNamed) {
  const auto dir = basalt::test::scratch_dir("packer-cli-names");
  const std::string o = " -o " + (dir / "x.h5").string();
  auto r = run("torus --rmin 0.2 --rmax 0.5" + o);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "unknown shape 'torus'")) << r.output;
  EXPECT_TRUE(contains(r.output, "box, cylinder, sphere or mesh")) << r.output;
  r = run("");
  EXPECT_NE(r.status, 0);
  EXPECT_TRUE(contains(r.output, "no shape given")) << r.output;
  EXPECT_EQ(run("--help").status, 0);
  struct Case {
    const char* seed;
    const char* words;
  };
  for (const Case& c : {Case{"-1", "a seed cannot be negative"}, Case{"-0", "a seed cannot be negative"},
                        Case{"1.5", "not a whole number"}, Case{"7x", "not a whole number"},
                        Case{"18446744073709551616", "too large"}}) {
    r = run(std::string("box --size 3,3,3 --rmin 0.2 --rmax 0.5 --seed ") + c.seed + o);
    EXPECT_EQ(r.status, 1) << c.seed << ": " << r.output;
    EXPECT_TRUE(contains(r.output, std::string("--seed '") + c.seed + "': " + c.words)) << r.output;
  }
  EXPECT_FALSE(fs::exists(dir / "x.h5"));
  // The largest seed is a seed, stored as given.
  r = run("box --size 3,3,3 --rmin 0.2 --rmax 0.5 -q --seed 18446744073709551615" + o);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(basalt::io::read_geometry(dir / "x.h5").attributes.at("seed"), "18446744073709551615");
}

TEST(Cli, ThreadCountChangesNothingInTheFile) {
  // 20 x 20 mm with rmax 0.5: 4 x 4 tiles packed on 1 and on 3 threads (docs/packer.md, "Tiles and threads").
  const auto dir = basalt::test::scratch_dir("packer-cli-threads");
  std::string bytes[2];
  for (int k = 0; k < 2; ++k) {
    const auto out = dir / ("slab" + std::to_string(k) + ".h5");
    const auto r = run("box --size 20,20,3 --rmin 0.25 --rmax 0.5 --exponent 2.2 --fill --seed 4 --threads " +
                       std::to_string(1 + 2 * k) + " -o " + out.string());
    ASSERT_EQ(r.status, 0) << r.output;
    bytes[k] = slurp(out);
  }
  EXPECT_GT(bytes[0].size(), 10000u);
  EXPECT_TRUE(bytes[0] == bytes[1]) << "--threads 1 and --threads 3 wrote different files";
  const auto bad = run("box --size 5,5,5 --rmin 0.2 --rmax 1 --threads 0 -o " + (dir / "x.h5").string());
  EXPECT_EQ(bad.status, 1);
  EXPECT_TRUE(contains(bad.output, "--threads must be >= 1, got 0")) << bad.output;
}
