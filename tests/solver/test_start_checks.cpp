// The state a run starts from is checked before the first step: coincident particles are refused
// (naming both ids and their distance) instead of producing NaN at step 1; particles overlapping each
// other or a wall by more than half a radius are refused unless forced.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/simulation.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;

namespace {

const std::string kContacts = R"(
[run]
dt = 1e-3
steps = 0
skin = 0.05
[[interactions]]
type = "linear_elastic"
K = 100.0
)";

basalt::io::Geometry two(double distance, bool bonded = false) {
  basalt::io::Geometry g;
  g.add_particle(7, {0, 0, 0}, 0.5);
  g.add_particle(9, {distance, 0, 0}, 0.5);
  if (bonded) g.bonds.push_back({7, 9, 0});
  return g;
}

std::string error_of(const std::string& scene, const basalt::io::Geometry& g, bool force = false) {
  auto opt = basalt::test::quiet();
  opt.force_overlap = force;
  try {
    Simulation<double> sim(basalt::test::scene_from(scene), g, MPI_COMM_SELF, opt);
    sim.run(5);
    for (std::size_t i = 0; i < sim.particles().n_owned; ++i)
      if (!std::isfinite(sim.particles().x[i])) return "non-finite";
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(StartChecks, CoincidentParticlesAreRefusedNamingBoth) {
  for (const double d : {0.0, 1e-200, 1e-12}) {
    const auto msg = error_of(kContacts, two(d));
    EXPECT_NE(msg.find("id 7 and id 9"), std::string::npos) << d << ": " << msg;
    EXPECT_NE(msg.find("coincident"), std::string::npos) << d << ": " << msg;
  }
  // Bonded and coincident: the bond's force would divide by zero.
  const std::string bonds = R"(
[run]
dt = 1e-3
steps = 0
skin = 0.05
[[interactions]]
type = "linear_bond"
K = 100.0
)";
  EXPECT_NE(error_of(bonds, two(0.0, true)).find("coincident"), std::string::npos);
}

TEST(StartChecks, DeepOverlapsAreRefusedUnlessForced) {
  EXPECT_EQ(error_of(kContacts, two(0.95)), "");   // 10 % of a radius: fine
  const auto msg = error_of(kContacts, two(0.1));  // 90 %
  EXPECT_NE(msg.find("id 7 and id 9 overlap by 1.8"), std::string::npos) << msg;
  EXPECT_NE(msg.find("force_overlap"), std::string::npos) << msg;
  EXPECT_EQ(error_of(kContacts, two(0.1), /*force=*/true), "");
  // The same through the scene key.
  std::string forced = kContacts;
  forced.replace(forced.find("skin = 0.05"), 11, "skin = 0.05\nforce_overlap = true");
  EXPECT_EQ(error_of(forced, two(0.1)), "");
}

TEST(StartChecks, ParticleDeepInAWallIsRefusedNamingTheWall) {
  const std::string wall = kContacts + R"(
[[walls]]
name = "floor"
point = [0.0, 0.0, 0.3]
normal = [0.0, 0.0, 1.0]
K = 100.0
)";
  const auto msg = error_of(wall, two(1.0));  // centres at z = 0, 0.3 below the plane
  EXPECT_NE(msg.find("wall \"floor\""), std::string::npos) << msg;
  EXPECT_NE(msg.find("id 7"), std::string::npos) << msg;
}

TEST(StartChecks, ParticleDeepInAMeshWallIsRefusedNamingTheMesh) {
  // A flat mesh floor (two triangles over [-2, 2]^2) at height h; the particles' centres are at z = 0
  // with radius 0.5: h = 0.1 overlaps by 0.8 of the radius (refused unless forced), h = -0.45 by 0.1
  // (accepted), h = -0.6 not at all.
  const auto dir = basalt::test::scratch_dir("start-checks-mesh");
  const auto floor = [&](double h) {
    const auto file = dir / ("floor" + std::to_string(h) + ".obj");
    std::ofstream out(file);
    out << "v -2 -2 " << h << "\nv 2 -2 " << h << "\nv 2 2 " << h << "\nv -2 2 " << h
        << "\nf 1 2 3\nf 1 3 4\n";
    return kContacts + "[[mesh_walls]]\nname = \"floor\"\nfile = \"" + file.string() + "\"\nK = 100.0\n";
  };
  const auto msg = error_of(floor(0.1), two(1.0));
  EXPECT_NE(msg.find("mesh wall \"floor\" by 0.8"), std::string::npos) << msg;
  EXPECT_NE(msg.find("force_overlap"), std::string::npos) << msg;
  EXPECT_EQ(error_of(floor(0.1), two(1.0), /*force=*/true), "");
  EXPECT_EQ(error_of(floor(-0.45), two(1.0)), "");
  EXPECT_EQ(error_of(floor(-0.6), two(1.0)), "");
}
