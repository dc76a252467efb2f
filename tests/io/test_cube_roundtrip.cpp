// The real GenGeo packing (tests/data/cube1.geo) through both formats and back:
// .geo -> .h5 -> .geo loses nothing (ids, exact positions, radii, tags, bonds), and the
// rewritten .geo has the original's particle lines, character for character.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "basalt/io/geometry.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace basalt::io;

namespace {

/// Particle lines of a .geo file keyed by id (the fifth field); bond lines as read, in order.
struct GeoLines {
  std::map<std::int64_t, std::string> particles;
  std::vector<std::string> bonds;
};

GeoLines geo_lines(const fs::path& file) {
  std::ifstream in(file);
  GeoLines out;
  std::string line;
  enum { kHeader, kParticles, kBetween, kBonds } state = kHeader;
  std::size_t remaining = 0;
  while (std::getline(in, line)) {
    if (state == kHeader && line == "Simple") {
      std::getline(in, line);
      remaining = std::stoul(line);
      state = kParticles;
    } else if (state == kParticles && remaining > 0) {
      std::istringstream f(line);
      std::string x, y, z, r;
      std::int64_t id = 0;
      f >> x >> y >> z >> r >> id;
      EXPECT_TRUE(out.particles.emplace(id, line).second) << "duplicate id in " << file;
      if (--remaining == 0) state = kBetween;
    } else if (state == kBetween && line == "BeginConnect") {
      std::getline(in, line);
      remaining = std::stoul(line);
      state = kBonds;
    } else if (state == kBonds && remaining > 0) {
      out.bonds.push_back(line);
      --remaining;
    }
  }
  return out;
}

}  // namespace

TEST(CubeRoundTrip, GenGeoPackingThroughH5AndBackToGeo) {
  const auto original = basalt::test::reference_dir() / "cube1.geo";
  ASSERT_TRUE(fs::exists(original)) << original;
  const auto dir = basalt::test::scratch_dir("cube-roundtrip");

  const Geometry g = read_geometry(original);
  ASSERT_EQ(g.size(), 8948u);
  ASSERT_EQ(g.bonds.size(), 30090u);
  EXPECT_EQ(g.box_min, (Vec3{0, 0, 0}));
  EXPECT_EQ(g.box_max, (Vec3{15, 15, 15}));
  EXPECT_EQ(g.periodic, (std::array<bool, 3>{false, false, false}));
  EXPECT_TRUE(std::is_sorted(g.id.begin(), g.id.end()));
  EXPECT_EQ(g.attributes.at("source_file"), "cube1.geo");

  write_geometry(g, dir / "cube.h5");
  const Geometry h = read_geometry(dir / "cube.h5");
  basalt::io::test::expect_same_particles_and_bonds(h, g);
  EXPECT_EQ(h.box_max, g.box_max);
  EXPECT_EQ(h.attributes, g.attributes);

  write_geometry(h, dir / "cube.geo");
  const Geometry back = read_geometry(dir / "cube.geo");
  basalt::io::test::expect_same_particles_and_bonds(back, g);
  EXPECT_EQ(back.box_min, g.box_min);
  EXPECT_EQ(back.box_max, g.box_max);

  // Text: every particle line is reproduced exactly (Basalt writes particles sorted by id,
  // GenGeo in insertion order, so lines are compared by id); bonds keep their order and text
  // where GenGeo already stored the smaller id first.
  const auto before = geo_lines(original);
  const auto after = geo_lines(dir / "cube.geo");
  ASSERT_EQ(before.particles.size(), 8948u);
  ASSERT_EQ(after.particles.size(), 8948u);
  std::size_t differing = 0;
  for (const auto& [id, line] : before.particles) {
    auto it = after.particles.find(id);
    ASSERT_NE(it, after.particles.end()) << "id " << id << " missing from the rewritten file";
    if (it->second != line && differing++ < 5)
      ADD_FAILURE() << "particle " << id << ":\n  GenGeo: " << line << "\n  Basalt: " << it->second;
  }
  EXPECT_EQ(differing, 0u);
  ASSERT_EQ(after.bonds.size(), before.bonds.size());
  std::size_t bonds_differing = 0;
  for (std::size_t k = 0; k < before.bonds.size(); ++k) {
    std::istringstream f(before.bonds[k]);
    std::int64_t a = 0, b = 0, tag = 0;
    f >> a >> b >> tag;
    if (a > b) std::swap(a, b);
    const auto expected = fmt::format("{} {} {}", a, b, tag);
    if (after.bonds[k] != expected && bonds_differing++ < 5)
      ADD_FAILURE() << "bond " << k << ": expected '" << expected << "', found '" << after.bonds[k] << "'";
  }
  EXPECT_EQ(bonds_differing, 0u);
}
