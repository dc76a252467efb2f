// Issue 16, overflowing parameters and input hygiene: what the scene's numbers make with the geometry's
// (masses, k dt^2 / m, wall steps) is checked at load and refused naming the scene key; scene parts that
// match no particle are warnings naming the group; two savers of one column and a scene larger than
// 10 MB are refused.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/scene/load_checks.hpp"
#include "basalt/solver/simulation.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;
using basalt::test::scene_from;

namespace {

const std::string kRun = R"(
[run]
dt = 1e-3
steps = 0
skin = 0.05
)";

const std::string kBonds = R"(
[[interactions]]
name = "springs"
type = "linear_bond"
K = 100.0
)";

/// Two bonded particles of radius 0.5, 1 apart, tags 0 and 1.
basalt::io::Geometry pair_geometry() {
  basalt::io::Geometry g;
  g.add_particle(1, {0, 0, 1}, 0.5, 0);
  g.add_particle(2, {1, 0, 1}, 0.5, 1);
  g.bonds.push_back({1, 2, 0});
  return g;
}

/// The InputError's text for this scene (load checks only), or "" when accepted.
std::string load_error(const std::string& scene, const basalt::io::Geometry& g = pair_geometry()) {
  try {
    (void)check_scene_with_geometry(scene_from(scene), g, "pair.geo");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::vector<std::string> load_warnings(const std::string& scene,
                                       const basalt::io::Geometry& g = pair_geometry()) {
  return check_scene_with_geometry(scene_from(scene), g, "pair.geo");
}

std::string wall(const std::string& motion, const std::string& extra = "") {
  return "[[walls]]\nname = \"floor\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nK = 100.0\n" +
         extra + "motion = " + motion + "\n";
}

#define EXPECT_HAS(text, fragment) EXPECT_NE((text).find(fragment), std::string::npos) << (text)

}  // namespace

TEST(LoadChecks, ReasonableScenesPass) {
  EXPECT_EQ(load_error(kRun + kBonds), "");
  EXPECT_EQ(load_error(kRun + kBonds + wall("{ type = \"half_sine\", amplitude = 0.1, period = 1.0 }")), "");
  EXPECT_EQ(load_error("[material]\ndensity = 2.7e-3\n" + kRun + kBonds), "");
  EXPECT_TRUE(load_warnings(kRun + kBonds).empty());
}

TEST(LoadChecks, MassesThatAreNotFiniteNameTheDensity) {
  // 1e308 x 4/3 pi 0.125 overflows; 1e-320 gives a mass whose inverse overflows.
  for (const char* density : {"1e308", "1.5e308", "1e-320"}) {
    const auto msg = load_error(std::string("[material]\ndensity = ") + density + "\n" + kRun + kBonds);
    EXPECT_HAS(msg, "material.density = ");
    EXPECT_HAS(msg, "particle id 1 (radius 0.5)");
    EXPECT_HAS(msg, "must be finite and > 0, with a finite inverse");
  }
  // Masses given by the geometry (or a checkpoint) name it.
  auto g = pair_geometry();
  g.mass = {1.0, 1e-320};
  const auto msg = load_error(kRun + kBonds, g);
  EXPECT_HAS(msg, "pair.geo: particle id 2 has the mass");
}

TEST(LoadChecks, SpringsThatOverflowNameTheGroupAndKey) {
  // k dt^2 / m overflows: a huge stiffness with a long step, or a stiff spring on a tiny mass.
  std::string slow_run = kRun;
  slow_run.replace(slow_run.find("1e-3"), 4, "1.0");
  std::string huge_k = kBonds;
  huge_k.replace(huge_k.find("100.0"), 5, "1e308");
  auto msg = load_error(slow_run + huge_k);
  EXPECT_HAS(msg, "interactions \"springs\" (type = \"linear_bond\"), key K");
  EXPECT_HAS(msg, "k dt^2 / m = inf");

  std::string stiff = kBonds;
  stiff.replace(stiff.find("100.0"), 5, "1e300");
  msg = load_error("[material]\ndensity = 1e-16\n" + kRun + stiff);
  EXPECT_HAS(msg, "interactions \"springs\"");
  EXPECT_HAS(msg, "material.density = 1e-16");
  EXPECT_EQ(load_error(kRun + stiff), "");  // finite: the time-step check speaks for it

  // A wall whose ESyS-style stiffness pi r K overflows.
  const std::string esys =
      "[[walls]]\nname = \"floor\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n"
      "K = 1.7e308\nstiffness = \"esys_pi_r\"\n";
  msg = load_error(kRun + kBonds + esys);
  EXPECT_HAS(msg, "walls[0] (\"floor\") (type = \"elastic\"), key K");
  EXPECT_HAS(msg, "k = inf");

  // A contact group too.
  msg = load_error(slow_run + "[[interactions]]\nname = \"touch\"\ntype = \"linear_elastic\"\nK = 1e308\n");
  EXPECT_HAS(msg, "interactions \"touch\" (type = \"linear_elastic\"), key K");
}

TEST(LoadChecks, WallsThatJumpOverParticlesNameTheMotionKey) {
  for (const char* amplitude : {"1e300", "1e4", "501.0"}) {
    const auto msg =
        load_error(kRun + kBonds +
                   wall(std::string("{ type = \"sine\", amplitude = ") + amplitude + ", period = 1.0 }"));
    EXPECT_HAS(msg, "walls[0] (\"floor\") motion.amplitude = ");
    EXPECT_HAS(msg, "the smallest particle radius 0.5");
    EXPECT_HAS(msg, "particles would pass through it");
  }
  // 1e200 in every component overflows the speed itself.
  auto msg =
      load_error(kRun + kBonds + wall("{ type = \"constant_velocity\", velocity = [1e200, 1e200, 1e200] }"));
  EXPECT_HAS(msg, "walls[0] (\"floor\") motion.velocity = [1e+200, 1e+200, 1e+200]");
  msg = load_error(kRun + kBonds + wall("{ type = \"constant_velocity\", velocity = [0.0, 0.0, 499.0] }"));
  EXPECT_EQ(msg, "");  // 0.499 per step: less than a radius
}

TEST(LoadChecks, TheSimulationRefusesBeforeItStarts) {
  const auto opt = basalt::test::quiet();
  const auto scene = scene_from("[material]\ndensity = 1e308\n" + kRun + kBonds);
  try {
    Simulation<double> sim(scene, pair_geometry(), MPI_COMM_SELF, opt);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_HAS(std::string(e.what()), "material.density = 1e+308");
  }
}

TEST(InputHygiene, TagsThatMatchNoParticleAreWarningsNamingTheGroup) {
  // Pair group: tag 7 is in no particle.
  auto w = load_warnings(kRun +
                         "[[interactions]]\nname = \"mixed\"\ntype = \"linear_elastic\"\nK = 1.0\n"
                         "tags = [0, 7]\n");
  ASSERT_EQ(w.size(), 1u);
  EXPECT_HAS(w[0], "interactions \"mixed\": tags = [0, 7]");
  EXPECT_HAS(w[0], "has tag 7");
  EXPECT_HAS(w[0], "present: 0, 1");
  // Bond group with tags no particle has, and a bond_tag no bond has.
  w = load_warnings(kRun +
                    "[[interactions]]\nname = \"glue\"\ntype = \"linear_bond\"\nK = 1.0\ntags = [5, 6]\n"
                    "bond_tag = 3\n");
  ASSERT_EQ(w.size(), 2u);
  EXPECT_HAS(w[0], "interactions \"glue\": tags = [5, 6]");
  EXPECT_HAS(w[0], "tags 5, 6");
  EXPECT_HAS(w[1], "interactions \"glue\": bond_tag = 3");
  // A wall and a body force.
  w = load_warnings(kRun + kBonds + wall("{ type = \"fixed\" }", "tags = [1, 9]\n") +
                    "[[body_forces]]\nname = \"g\"\ntype = \"gravity\"\nacceleration = [0.0, 0.0, -1e-5]\n"
                    "tags = [4]\n");
  ASSERT_EQ(w.size(), 2u);
  EXPECT_HAS(w[0], "walls[0] (\"floor\"): tags = [1, 9]");
  EXPECT_HAS(w[1], "body_forces \"g\": tags = [4]");
  // Tags that exist: no warning.
  EXPECT_TRUE(
      load_warnings(kRun + "[[interactions]]\ntype = \"linear_elastic\"\nK = 1.0\ntags = [1, 0]\n").empty());
}

TEST(InputHygiene, TwoSaversOfOneColumnAreRefused) {
  auto error_of = [](const std::string& fields) {
    try {
      (void)scene_from(kRun + kBonds + wall("{ type = \"fixed\" }") + "[output]\n" + fields);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string ke = "[[output.fields]]\ntype = \"kinetic_energy\"\n";
  auto msg = error_of(ke + ke);
  EXPECT_HAS(msg, "output.fields[1].type");
  EXPECT_HAS(msg, "\"kinetic_energy\" is saved already by output.fields[0]");
  msg = error_of(ke +
                 "[[output.fields]]\ntype = \"bond_count\"\nevery = 5\n[[output.fields]]\ntype = "
                 "\"bond_count\"\nevery = 10\n");
  EXPECT_HAS(msg, "output.fields[2].type");
  EXPECT_HAS(msg, "output.fields[1]");
  const std::string wf = "[[output.fields]]\ntype = \"wall_force\"\nwall = \"floor\"\n";
  msg = error_of(wf + wf);
  EXPECT_HAS(msg, "output.fields[1].wall");
  EXPECT_HAS(msg, "wall_force_floor_x/y/z");
  EXPECT_EQ(error_of(ke + wf + "[[output.fields]]\ntype = \"total_energy\"\n"), "");
}

TEST(InputHygiene, ScenesLargerThanTenMegabytesAreRefused) {
  const std::string big = kRun + kBonds + "# " + std::string(10'000'001, 'x') + "\n";
  try {
    (void)scene_from(big);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_HAS(std::string(e.what()), "test.toml: the scene is 10.0 MB, more than the 10 MB");
  }
  // From a file: refused before it is read.
  const auto file = basalt::test::scratch_dir("load-checks") / "big.toml";
  {
    std::ofstream out(file);
    out << "[geometry]\nfile = \"x.geo\"\n" << big;
  }
  try {
    (void)parse_scene(file);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_HAS(std::string(e.what()), "big.toml: the scene is 10.0 MB");
  }
  // A comment of 1 MB is fine.
  EXPECT_NO_THROW((void)scene_from(kRun + kBonds + "# " + std::string(1'000'000, 'x') + "\n"));
}

// Strain resolution of positions (issue 16, precision limits): eps |x|max / (2 rmin); nothing below 1e-5,
// a warning naming the resolution and the remedy up to 1e-4, refused above.
TEST(LoadChecks, PrecisionOfFarCoordinates) {
  auto at = [](double d) {
    basalt::io::Geometry g = pair_geometry();
    for (auto& x : g.position) x[0] += d;
    return summarize_geometry(scene_from(kRun), g, "pair.geo");
  };
  constexpr double kFloat = 1.1920929e-7, kDouble = 2.220446049250313e-16;
  EXPECT_NEAR(strain_resolution(at(99), kFloat), kFloat * 100 / 1.0, 1e-12);
  EXPECT_EQ(check_precision(at(0), kFloat, "float", "pair.geo"), "");           // 1.2e-7
  EXPECT_EQ(check_precision(at(1e9), kDouble, "double", "pair.geo"), "");       // 2.2e-7
  const std::string w = check_precision(at(200), kFloat, "float", "pair.geo");  // 2.4e-5
  EXPECT_NE(w.find("pair.geo: coordinates reach |x| = 201"), std::string::npos) << w;
  EXPECT_NE(w.find("in float a distance between particles there is rounded to a strain of 2.4e-05"),
            std::string::npos)
      << w;
  EXPECT_NE(w.find("run in double"), std::string::npos) << w;
  EXPECT_NE(
      check_precision(at(1e11), kDouble, "double", "pair.geo").find("move the geometry nearer the origin"),
      std::string::npos);
  for (auto [d, eps] : {std::pair{1e3, kFloat}, std::pair{1e5, kFloat}, std::pair{1e12, kDouble}}) {
    try {
      (void)check_precision(at(d), eps, eps == kFloat ? "float" : "double", "pair.geo");
      ADD_FAILURE() << "offset " << d << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("above the limit 0.0001"), std::string::npos) << e.what();
    }
  }
}
