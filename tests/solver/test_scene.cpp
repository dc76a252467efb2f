// The scene parser: the shipped scenes parse; every kind of bad input names the line and key.
#include <gtest/gtest.h>

#include <string>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/models/elastic_wall.hpp"
#include "basalt/solver/models/linear_bond.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;

namespace {

const std::string kGood = R"(
[run]
dt = 1e-3
steps = 10
skin = 0.1

[[interactions]]
type = "linear_bond"
K = 1000.0

[[walls]]
name = "base"
point = [0, 0, 0]
normal = [0, 0, 2]
K = 1000.0
motion = { type = "half_sine", amplitude = 0.1, period = 1.0 }
)";

/// Parses text that must fail; returns the message.
std::string error_of(const std::string& text) {
  try {
    basalt::test::scene_from(text);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return "";
}

}  // namespace

TEST(Scene, ShippedScenesParse) {
  for (const char* name : {"wave.toml", "wave-esys.toml"}) {
    const auto s = parse_scene(basalt::test::source_dir() / "scenes" / name);
    EXPECT_DOUBLE_EQ(s.dt, 1e-3);
    EXPECT_EQ(s.steps, 10000);
    ASSERT_EQ(s.bonds.size(), 1u);
    ASSERT_EQ(s.contacts.size(), 1u);
    ASSERT_EQ(s.walls.size(), 1u);
    EXPECT_EQ(s.walls[0].motion.type, WallMotion::Type::half_sine);
    EXPECT_DOUBLE_EQ(s.walls[0].motion.amplitude, 0.1);
    ASSERT_EQ(s.fields.size(), 1u);
    EXPECT_EQ(s.fields[0].every, 1);
    EXPECT_EQ(field_columns(s), std::vector<std::string>{"kinetic_energy"});
  }
  const auto esys = parse_scene(basalt::test::source_dir() / "scenes" / "wave-esys.toml");
  EXPECT_EQ(esys.bonds[0].params_of<LinearBond>().rest_length, LinearBond::RestLength::sum_of_radii);
  EXPECT_EQ(esys.walls[0].params_of<ElasticWall>().stiffness, ElasticWall::Stiffness::esys_pi_r);
  EXPECT_EQ(esys.integrator, Integrator::symplectic_euler);
  const auto wave = parse_scene(basalt::test::source_dir() / "scenes" / "wave.toml");
  EXPECT_EQ(wave.bonds[0].params_of<LinearBond>().rest_length, LinearBond::RestLength::initial_distance);
  EXPECT_EQ(wave.geometry, basalt::test::source_dir() / "scenes" / "../out/cube.h5");
}

TEST(Scene, GoodSceneValues) {
  const auto s = basalt::test::scene_from(kGood);
  EXPECT_DOUBLE_EQ(s.walls[0].normal[2], 1.0);  // normalised
  EXPECT_TRUE(std::isinf(s.bonds[0].params_of<LinearBond>().break_strain));
  EXPECT_EQ(s.integrator, Integrator::velocity_verlet);
}

TEST(Scene, UnknownKeyNamesLineAndKey) {
  std::string text = kGood;
  text.replace(text.find("skin = 0.1"), 10, "skin = 0.1\nsteps_ = 3");
  const auto msg = error_of(text);
  EXPECT_NE(msg.find("test.toml:8"), std::string::npos) << msg;  // the [geometry] prefix adds two lines
  EXPECT_NE(msg.find("run.steps_"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unknown key"), std::string::npos) << msg;
}

TEST(Scene, MisspelledInteractionKey) {
  std::string text = kGood;
  text.replace(text.find("K = 1000.0"), 10, "k = 1000.0");
  const auto msg = error_of(text);
  EXPECT_NE(msg.find("interactions[0].K"), std::string::npos) << msg;
  EXPECT_NE(msg.find("missing"), std::string::npos) << msg;
}

TEST(Scene, WrongType) {
  std::string text = kGood;
  text.replace(text.find("steps = 10"), 10, "steps = \"ten\"");
  const auto msg = error_of(text);
  EXPECT_NE(msg.find("test.toml:6: run.steps: must be an integer"), std::string::npos) << msg;
}

TEST(Scene, ImpossibleValues) {
  auto with = [](const std::string& from, const std::string& to) {
    std::string t = kGood;
    t.replace(t.find(from), from.size(), to);
    return error_of(t);
  };
  auto msg = with("dt = 1e-3", "dt = 0.0");
  EXPECT_NE(msg.find("run.dt: must be > 0"), std::string::npos) << msg;
  msg = with("dt = 1e-3", "dt = -1e-3");
  EXPECT_NE(msg.find("run.dt"), std::string::npos) << msg;
  // Issue 16: infinity is named as not finite, not as "must be > 0".
  msg = with("dt = 1e-3", "dt = inf");
  EXPECT_NE(msg.find("run.dt: must be a finite number > 0, got inf"), std::string::npos) << msg;
  msg = with("type = \"linear_bond\"\nK = 1000.0", "type = \"linear_bond\"\nK = nan");
  EXPECT_NE(msg.find("interactions[0].K: must be a finite number >= 0"), std::string::npos) << msg;
  msg = with("type = \"linear_bond\"\nK = 1000.0", "type = \"linear_bond\"\nK = -5.0");
  EXPECT_NE(msg.find("interactions[0].K: must be >= 0"), std::string::npos) << msg;
  msg = with("normal = [0, 0, 2]", "normal = [0, 0, 0]");
  EXPECT_NE(msg.find("walls[0].normal: must have non-zero length"), std::string::npos) << msg;
  EXPECT_NE(msg.find("test.toml:16"), std::string::npos) << msg;
  msg = with("motion = { type = \"half_sine\", amplitude = 0.1, period = 1.0 }",
             "motion = { type = \"ramp\", velocity = [0, 0, 1], ramp_time = 0.1, start_time = -0.2 }");
  EXPECT_NE(msg.find("start_time: must be finite and >= -ramp_time"), std::string::npos) << msg;
  msg = with("period = 1.0", "period = 0.0");
  EXPECT_NE(msg.find("walls[0].motion.period"), std::string::npos) << msg;
  msg = with("type = \"half_sine\"", "type = \"half-sine\"");
  EXPECT_NE(msg.find("walls[0].motion.type"), std::string::npos) << msg;
  msg = with("type = \"linear_bond\"", "type = \"linear_bonds\"");
  EXPECT_NE(msg.find("interactions[0].type"), std::string::npos) << msg;
  msg = with("skin = 0.1", "skin = 0.1\nintegrator = \"rk4\"");
  EXPECT_NE(msg.find("run.integrator"), std::string::npos) << msg;
}

TEST(Scene, FieldsAndOutput) {
  const auto s = basalt::test::scene_from(kGood + R"(
[output]
directory = "here"
[[output.fields]]
type = "kinetic_energy"
every = 5
[[output.fields]]
type = "wall_force"
wall = "base"
)");
  EXPECT_EQ(field_columns(s), (std::vector<std::string>{"kinetic_energy", "wall_force_base_x",
                                                        "wall_force_base_y", "wall_force_base_z"}));
  auto msg = error_of(kGood + "[output]\n[[output.fields]]\ntype = \"wall_force\"\nwall = \"top\"\n");
  EXPECT_NE(msg.find("output.fields[0].wall: no wall named \"top\""), std::string::npos) << msg;
  msg = error_of(kGood + "[output]\n[[output.fields]]\ntype = \"kinetic_energy\"\nevery = 0\n");
  EXPECT_NE(msg.find("output.fields[0].every"), std::string::npos) << msg;
  msg = error_of(kGood + "[output]\n[[output.fields]]\ntype = \"kinetic\"\n");
  EXPECT_NE(msg.find("output.fields[0].type"), std::string::npos) << msg;
}

// Issue 48: an empty path names its key and says it is empty (were "cases/scenes/: is a folder, not a
// file" and ": cannot create the output folder: Invalid argument").
TEST(Scene, EmptyPathsNameTheKey) {
  auto msg = [] {
    try {
      (void)parse_scene_text("[geometry]\nfile = \"\"\n" + kGood, "test.toml", "cases/scenes");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  }();
  EXPECT_NE(msg.find("test.toml:2: geometry.file: is empty"), std::string::npos) << msg;
  msg = error_of(kGood + "[output]\ndirectory = \"\"\n");
  EXPECT_NE(msg.find("output.directory: is empty"), std::string::npos) << msg;
  msg = error_of(kGood + "[[mesh_walls]]\nname = \"m\"\nfile = \"\"\nK = 1.0\n");
  EXPECT_NE(msg.find("mesh_walls[0].file: is empty"), std::string::npos) << msg;
}

// Issue 48: two savers of one kind with other parameters both save, under distinct column names (a second
// runout was refused as a duplicate column); identical ones are still refused.
TEST(Scene, SaversOfOneKindWithOtherParametersAreAllowed) {
  const std::string runout = "[[output.fields]]\ntype = \"runout\"\n";
  const auto s = basalt::test::scene_from(kGood + "[output]\n" + runout + "percentile = 100\n" + runout +
                                          "percentile = 99\n" + runout + "percentile = 99.4\n" + runout +
                                          "percentile = 99\ndirection = [0.0, 1.0, 0.0]\n" + runout +
                                          "percentile = 99\norigin = [1.0, 0.0, 0.0]\n" +
                                          "[[output.fields]]\ntype = \"mass_below\"\nz = "
                                          "1.0\n[[output.fields]]\ntype = \"mass_below\"\nz = 2.0\n");
  EXPECT_EQ(field_columns(s),
            (std::vector<std::string>{"runout_max", "runout_p99", "runout_p99_4", "runout_p99_fields3",
                                      "runout_p99_fields4", "mass_below", "mass_below_fields6"}));
  auto msg = error_of(kGood + "[output]\n" + runout + "percentile = 99\nevery = 2\n" + runout +
                      "percentile = 99\nevery = 5\n");
  EXPECT_NE(
      msg.find("output.fields[1].type: \"runout_p99\" is saved already by output.fields[0] with the same "
               "parameters"),
      std::string::npos)
      << msg;
  msg = error_of(kGood + "[output]\n" + runout + "direction = [0.0, 0.0, 1.0]\n" + runout +
                 "direction = [0.0, 0.0, 2.0]\n");  // the same unit direction
  EXPECT_NE(msg.find("\"runout_max\" is saved already"), std::string::npos) << msg;
}

TEST(Scene, MissingTablesAndSyntax) {
  auto msg = error_of(kGood + "[geometryy]\nfile = \"x\"\n");
  EXPECT_NE(msg.find("geometryy: unknown key"), std::string::npos) << msg;
  msg = error_of("[run]\ndt = \n");
  EXPECT_NE(msg.find("test.toml:4"), std::string::npos) << msg;
  msg = error_of("[material]\ndensity = 1.0\n");
  EXPECT_NE(msg.find("run: missing"), std::string::npos) << msg;
  EXPECT_THROW(parse_scene("/nonexistent/scene.toml"), InputError);
}

TEST(WallMotion, HalfSineDisplacementIntegratesVelocity) {
  WallMotion m;
  m.type = WallMotion::Type::half_sine;
  m.amplitude = 0.1;
  m.period = 1.0;
  double u = 0;
  const double h = 1e-5;
  for (int k = 0; k < 100000; ++k) u += m.velocity_at((k + 0.5) * h)[2] * h;  // to t = 1
  EXPECT_NEAR(m.displacement_at(1.0)[2], u, 1e-9);
  EXPECT_NEAR(m.displacement_at(0.5)[2], 0.1 / std::numbers::pi, 1e-12);
  EXPECT_EQ(m.velocity_at(0.75)[2], 0.0);
  EXPECT_NEAR(m.velocity_at(0.25)[2], 0.1, 1e-12);
}

TEST(Scene, RotationalDampingOfParticlesThatDoNotRotateIsRefused) {
  // The scene's particles do not rotate (no model needs it): rotational damping has no angular velocity
  // to act on, and its iterated form would divide by a zero moment of inertia (NaN in the ledger).
  const std::string damping =
      "[[body_forces]]\ntype = \"rotational_damping\"\nviscosity = 0.1\niterations = 50\n";
  auto msg = error_of(kGood + damping);
  EXPECT_NE(msg.find("body_forces[0].type"), std::string::npos) << msg;
  EXPECT_NE(msg.find("particles.rotation = true"), std::string::npos) << msg;
  // With rotation on, it is taken.
  const auto s = basalt::test::scene_from(kGood + "[particles]\nrotation = true\n" + damping);
  ASSERT_EQ(s.body_forces.size(), 1u);
  EXPECT_TRUE(s.rotation);
}

TEST(Scene, OrientationsAreKeptWhenAModelReadsThemOrTheSceneAsks) {
  const std::string run = "[run]\ndt = 1e-3\nsteps = 10\nskin = 0.1\n";
  const std::string hertz =
      "[[interactions]]\ntype = \"hertz_mindlin\"\nE = 1e7\nnu = 0.25\ne = 0.5\nmu = 0.5\n";
  const std::string rot_bond =
      "[[interactions]]\ntype = \"rot_bond\"\nkn = 1000.0\nks = 400.0\nkb = 30.0\nkt = 20.0\n"
      "rest_length = \"sum_of_radii\"\n";
  // Rotating spheres whose models read no orientation: none kept, unless the scene asks.
  auto s = basalt::test::scene_from(run + hertz);
  EXPECT_TRUE(s.rotation);
  EXPECT_FALSE(s.orientation);
  s = basalt::test::scene_from(run + "[particles]\norientation = true\n" + hertz);
  EXPECT_TRUE(s.orientation);
  // A model that reads them (rot_bond's frames): kept without asking.
  s = basalt::test::scene_from(run + rot_bond);
  EXPECT_TRUE(s.rotation);
  EXPECT_TRUE(s.orientation);
  // Refused: leaving them out under such a model, or asking for them without rotation.
  auto msg = error_of(run + "[particles]\norientation = false\n" + rot_bond);
  EXPECT_NE(msg.find("particles.orientation = false"), std::string::npos) << msg;
  EXPECT_NE(msg.find("rot_bond"), std::string::npos) << msg;
  msg = error_of(kGood + "[particles]\norientation = true\n");
  EXPECT_NE(msg.find("particles.rotation = true"), std::string::npos) << msg;
}
