// The step's hooks and the steering calls between steps (Simulation::run with StepHook, set_dt,
// set_wall_velocity, remove_wall, set_fixed_tags), and the time step a scene chooses by run.dt_fraction
// reaching the velocity-dependent models (it did not: friction saw dt = 0). On 1 and 2 ranks.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/output/field_rows.hpp"
#include "basalt/solver/simulation.hpp"
#include "basalt/solver/stages.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"

using namespace basalt::solver;

namespace {

/// A frictional pile on a floor under gravity: a 4 x 4 x 3 lattice of spheres (radius 0.45-0.5), tag 1
/// for the bottom layer.
basalt::io::Geometry pile() {
  basalt::io::Geometry g;
  std::int64_t id = 1;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i, ++id) {
        const auto u = static_cast<std::uint64_t>(id);
        g.add_particle(id,
                       {0.5 + i + 0.05 * basalt::test::hash_unit(3 * u + 1),
                        0.5 + j + 0.05 * basalt::test::hash_unit(3 * u + 2), 0.48 + 0.98 * k},
                       0.475 + 0.025 * basalt::test::hash_unit(u), k == 0 ? 1 : 0);
      }
  return g;
}

std::string pile_scene(const std::string& step) {
  return R"(
[particles]
rotation = true
[run]
)" + step +
         R"(
steps = 0
skin = 0.1
[[interactions]]
type = "rot_friction"
K = 1000.0
Ks = 500.0
mu = 0.5
mu_dynamic = 0.4
[[walls]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
interaction = "friction"
K = 1000.0
Ks = 500.0
mu = 0.5
[[walls]]
name = "piston"
point = [0.0, 0.0, 10.0]
normal = [0.0, 0.0, -1.0]
K = 1000.0
[[body_forces]]
type = "gravity"
acceleration = [0.0, 0.0, -1.0]
)";
}

Simulation<double> make(const std::string& step) {
  return Simulation<double>(basalt::test::scene_from(pile_scene(step)), pile(), MPI_COMM_WORLD,
                            basalt::test::quiet());
}

/// id -> (x, y, z, vx, vy, vz) of every particle, gathered on every rank.
std::map<std::int64_t, std::vector<double>> state(const Simulation<double>& sim) {
  return basalt::test::gather_by_id(sim, [](const Particles<double>& p, std::size_t i) {
    return std::vector<double>{p.x[i], p.y[i], p.z[i], p.vx[i], p.vy[i], p.vz[i]};
  });
}

double lowest_z(const Simulation<double>& sim) {
  double z = 1e300;
  for (const auto& [id, s] : state(sim)) z = std::min(z, s[2]);
  return z;
}

}  // namespace

TEST(Steering, DtFractionReachesTheFrictionModels) {
  // The same pile with run.dt_fraction and with run.dt = the step that fraction chose: the same bits. Before
  // the fix the models kept the scene's dt (0) and friction's shear spring never loaded.
  auto a = make("dt_fraction = 0.2");
  const double dt = a.dt();
  ASSERT_GT(dt, 0);
  auto b = make(fmt::format("dt = {:.17g}", dt));
  ASSERT_EQ(b.dt(), dt);
  a.run(400);
  b.run(400);
  EXPECT_EQ(state(a), state(b));
}

TEST(Steering, HooksRunAtTheirStepsAndEndTheRunWithoutChangingIt) {
  auto a = make("dt = 2e-3");
  auto b = make("dt = 2e-3");
  std::vector<std::int64_t> seen;
  const StepHook hooks[] = {{10, [&](std::int64_t s) {
                               seen.push_back(s);
                               return s < 50;
                             }}};
  FieldRows rows(a.comm(), nullptr);
  EXPECT_EQ(a.run(1000, rows, hooks), 50);
  EXPECT_EQ(a.current_step(), 50);
  EXPECT_EQ(seen, (std::vector<std::int64_t>{10, 20, 30, 40, 50}));
  b.run(50);  // no hooks: deferred kicks throughout, the same bits
  EXPECT_EQ(state(a), state(b));
}

TEST(Steering, AHookSeesTheStepsVelocitiesUnlessItSaysItReadsNone) {
  // reads_velocities (the default): the step before the hook makes its second half-kick, so the hook sees
  // the velocities a run of exactly that many steps ends with. Without, the kick stays deferred: half a kick
  // of gravity behind.
  auto exact = make("dt = 2e-3");
  exact.run(10);
  const double want = exact.particles().vz[0];
  const auto seen = [](bool reads) {
    auto sim = make("dt = 2e-3");
    double vz = 0;
    const StepHook hooks[] = {{5,
                               [&](std::int64_t s) {
                                 if (s == 10) vz = sim.particles().vz[0];
                                 return true;
                               },
                               reads}};
    FieldRows rows(sim.comm(), nullptr);
    sim.run(20, rows, hooks);
    return vz;
  };
  EXPECT_EQ(seen(true), want);
  EXPECT_NE(seen(false), want);
}

TEST(Steering, SetDtChangesTheStepFromNowOn) {
  auto sim = make("dt = 2e-3");
  sim.set_wall_velocity("piston", {0, 0, -0.5});
  const double z0 = sim.walls().point(sim.wall_index("piston"))[2];
  sim.run(10);
  sim.set_dt(1e-3);
  EXPECT_EQ(sim.dt(), 1e-3);
  sim.run(10);
  // the wall's motion goes on with the clock: 0.02 at the old step, then 0.01 at the new one
  EXPECT_NEAR(sim.walls().point(sim.wall_index("piston"))[2] - z0, -0.5 * (10 * 2e-3 + 10 * 1e-3), 1e-12);
  EXPECT_NEAR(sim.time(), 10 * 2e-3 + 10 * 1e-3, 1e-15);  // the clock goes on at the new step, no jump
  EXPECT_THROW(sim.set_dt(0), InputError);
  EXPECT_THROW(sim.set_dt(-1), InputError);
}

TEST(Steering, SetDtAboveTheCriticalStepIsRefusedWithNothingChanged) {
  auto sim = make("dt = 2e-3");
  const double critical = sim.stability().dt_critical;
  ASSERT_GT(critical, 4e-3);  // the pile's step is far below it: the test needs room on both sides
  sim.run(5);
  const double t0 = sim.time();
  const auto before = state(sim);
  try {
    sim.set_dt(1.05 * critical);
    FAIL() << "dt above the critical step was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("dt (set at step 5)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("times the critical time step"), std::string::npos) << e.what();
  }
  EXPECT_EQ(sim.dt(), 2e-3);
  EXPECT_EQ(sim.stability().fraction, 2e-3 / critical);
  EXPECT_TRUE(sim.step_warnings().empty());
  sim.run(5);
  EXPECT_NEAR(sim.time(), t0 + 5 * 2e-3, 1e-15);  // the clock went on at the old step
  EXPECT_NE(state(sim), before);

  // Just below it: taken, and warned of (above the safe fraction); back to a small step: no warning.
  sim.set_dt(0.95 * critical);
  EXPECT_EQ(sim.dt(), 0.95 * critical);
  ASSERT_EQ(sim.step_warnings().size(), 1u);
  EXPECT_NE(sim.step_warnings()[0].find("above the safe fraction"), std::string::npos);
  sim.set_dt(2e-3);
  EXPECT_TRUE(sim.step_warnings().empty());
}

TEST(Steering, SetDtAboveTheSafeFractionWarnsInADtFractionScene) {
  // run.dt_fraction's own step is chosen knowingly and not warned of; a step a script sets later is.
  auto sim = make("dt_fraction = 0.9");
  EXPECT_TRUE(sim.step_warnings().empty());
  sim.set_dt(0.95 * sim.stability().dt_critical);
  ASSERT_EQ(sim.step_warnings().size(), 1u);
  EXPECT_NE(sim.step_warnings()[0].find("above the safe fraction"), std::string::npos);
}

TEST(Steering, SetDtAboveTheCriticalStepIsTakenWhenForced) {
  auto sim = make("dt = 2e-3\nforce_dt = true");
  const double critical = sim.stability().dt_critical;
  sim.set_dt(1.5 * critical);
  EXPECT_EQ(sim.dt(), 1.5 * critical);
  ASSERT_EQ(sim.step_warnings().size(), 1u);
  EXPECT_NE(sim.step_warnings()[0].find("(forced)"), std::string::npos);
}

TEST(Steering, AStageDtAboveTheCriticalStepIsRefusedAtTheStart) {
  // Not when the run reaches the stage, after the earlier stages' output: the scene is refused as it starts.
  const auto with_stage = [](double dt) {
    return pile_scene("dt = 2e-3") + fmt::format(R"(
[[stages]]
name = "settle"
steps = 10
[[stages]]
name = "fast"
steps = 10
dt = {}
)",
                                                 dt);
  };
  const double critical = make("dt = 2e-3").stability().dt_critical;
  EXPECT_NO_THROW(Simulation<double>(basalt::test::scene_from(with_stage(0.9 * critical)), pile(),
                                     MPI_COMM_WORLD, basalt::test::quiet()));
  try {
    Simulation<double>(basalt::test::scene_from(with_stage(1.1 * critical)), pile(), MPI_COMM_WORLD,
                       basalt::test::quiet());
    FAIL() << "a stage's dt above the critical step was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("stages[1] \"fast\": dt ="), std::string::npos) << e.what();
  }
}

TEST(Steering, AWallMovesAtTheVelocityGivenFromWhereItIs) {
  auto sim = make("dt = 2e-3");
  sim.run(20);
  const auto w = sim.wall_index("piston");
  const auto before = sim.walls().point(w);
  sim.set_wall_velocity("piston", {0, 0, -0.5});
  sim.run(100);
  const auto after = sim.walls().point(w);
  EXPECT_NEAR(after[2] - before[2], -0.5 * 100 * 2e-3, 1e-12);
  EXPECT_EQ(after[0], before[0]);
  EXPECT_THROW(sim.set_wall_velocity("nope", {0, 0, 0}), InputError);
}

TEST(Steering, RemovingTheFloorLetsThePileFall) {
  auto sim = make("dt = 2e-3");
  sim.run(300);  // settles on the floor
  const double z0 = lowest_z(sim);
  EXPECT_GT(z0, 0.3);
  sim.remove_wall("floor");
  sim.run(500);  // 1 time unit under g = 1: a free fall of 0.5
  EXPECT_LT(lowest_z(sim), z0 - 0.4);
}

TEST(Steering, FixedTagsHoldTheirParticlesFromNowOn) {
  auto sim = make("dt = 2e-3");
  sim.remove_wall("floor");
  sim.set_fixed_tags({1});  // the bottom layer holds the pile up
  const auto s0 = state(sim);
  sim.run(300);
  const auto s1 = state(sim);
  for (const auto& [id, s] : s1)
    if (id <= 16) {
      EXPECT_EQ(s[2], s0.at(id)[2]) << id;
    }
  sim.set_fixed_tags({});
  sim.run(300);
  const auto s2 = state(sim);
  EXPECT_LT(s2.at(1)[2], s0.at(1)[2] - 0.1);  // freed: it falls
}

TEST(Stages, SettleThenRemoveTheFloor) {
  // [[stages]]: settle until the kinetic energy is small (well before the bound), then take the floor away
  // and fall for a fixed number of steps.
  const auto scene = basalt::test::scene_from(pile_scene("dt = 2e-3") + R"(
[[body_forces]]
type = "linear_damping"
viscosity = 0.5
[[body_forces]]
type = "rotational_damping"
viscosity = 0.5
[[stages]]
name = "settle"
steps = 20000
until = { kinetic_energy_below = 1e-3, every = 50 }
[[stages]]
name = "fall"
remove_walls = ["floor"]
wall_velocity = { piston = [0.0, 0.0, -1.0] }
steps = 300
)");
  ASSERT_EQ(scene.stages.size(), 2u);
  Simulation<double> sim(scene, pile(), MPI_COMM_WORLD, basalt::test::quiet());
  FieldRows rows(sim.comm(), nullptr);
  std::vector<StageReport> reports;
  std::vector<double> lowest;
  const auto total = run_stages(sim, rows, scene.stages, [&](const StageSpec&, const StageReport& r) {
    reports.push_back(r);
    lowest.push_back(lowest_z(sim));  // the lowest particle at the stage's end
  });
  ASSERT_EQ(reports.size(), 2u);
  EXPECT_TRUE(reports[0].condition_met);
  EXPECT_LT(reports[0].steps, 20000);
  EXPECT_EQ(reports[0].steps % 50, 0);
  EXPECT_LT(reports[0].value, 1e-3);
  EXPECT_EQ(reports[1].first_step, reports[0].steps);
  EXPECT_EQ(reports[1].steps, 300);
  EXPECT_EQ(total, reports[0].steps + 300);
  EXPECT_EQ(sim.current_step(), total);
  ASSERT_EQ(lowest.size(), 2u);
  EXPECT_GT(lowest[0], 0.4);              // rested on the floor
  EXPECT_LT(lowest[1], lowest[0] - 0.1);  // then fell through where it was
  EXPECT_NEAR(sim.walls().point(sim.wall_index("piston"))[2], 10.0 - 300 * 2e-3, 1e-12);
}

TEST(Stages, ATimeConditionEndsTheStageAtTheFirstCheckPastIt) {
  // until = { time_above = T }: with dt = 2e-3 and checks every 10 steps, T = 0.105 is passed at step 60
  // (time 0.12; the check at step 50 sees 0.1). A second stage with a new dt goes on from there.
  const auto scene = basalt::test::scene_from(pile_scene("dt = 2e-3") + R"(
[[stages]]
name = "until_time"
steps = 1000
until = { time_above = 0.105, every = 10 }
[[stages]]
name = "finer"
dt = 1e-3
steps = 20
)");
  Simulation<double> sim(scene, pile(), MPI_COMM_WORLD, basalt::test::quiet());
  FieldRows rows(sim.comm(), nullptr);
  std::vector<StageReport> reports;
  run_stages(sim, rows, scene.stages, [&](const StageSpec& st, const StageReport& r) {
    reports.push_back(r);
    if (reports.size() == 1) {
      EXPECT_NE(describe(st, r).find("time 0.12 >= 0.105"), std::string::npos) << describe(st, r);
    }
  });
  ASSERT_EQ(reports.size(), 2u);
  EXPECT_TRUE(reports[0].condition_met);
  EXPECT_EQ(reports[0].steps, 60);
  EXPECT_EQ(sim.current_step(), 80);
  EXPECT_NEAR(sim.time(), 0.12 + 20 * 1e-3, 1e-12);
}

TEST(Stages, ASaverConditionEndsTheStageWhereItsColumnFirstPassesTheLimit) {
  // until = { saver = "mass_below", above = M }: the floor taken away, the pile falls through z = -0.5; the
  // stage ends at the first of the saver's rows (every 10 steps) whose value passes M, with the value the
  // row has. The kinetic energy saver beside it (every 1) moves mass_below to column 1.
  const auto scene = basalt::test::scene_from(pile_scene("dt = 2e-3") + R"(
[[output.fields]]
type = "kinetic_energy"
[[output.fields]]
type = "mass_below"
z = -0.5
every = 10
[[stages]]
name = "fall"
remove_walls = ["floor"]
steps = 5000
until = { saver = "mass_below", above = 6.0 }
)");
  ASSERT_EQ(scene.stages[0].every, 10);  // the saver's every, by default
  ASSERT_EQ(scene.stages[0].saver_column, 1u);
  Simulation<double> sim(scene, pile(), MPI_COMM_WORLD, basalt::test::quiet());
  basalt::test::MemorySink sink(scene);
  FieldRows rows(sim.comm(), &sink);
  StageReport report;
  std::string line;
  run_stages(sim, rows, scene.stages, [&](const StageSpec& st, const StageReport& r) {
    report = r;
    line = describe(st, r);
  });
  rows.finish();
  ASSERT_TRUE(report.condition_met) << line;
  EXPECT_EQ(report.steps % 10, 0);
  EXPECT_LT(report.steps, 5000);
  EXPECT_GT(report.value, 6.0);
  EXPECT_NE(line.find("mass_below"), std::string::npos) << line;
  if (sim.comm().rank() != 0) return;
  // The rows of fields.csv: the last one is the stage's last step with the value the stage saw; every
  // earlier row of the saver stays at or below the limit.
  const auto mass = sink.column(1);
  ASSERT_EQ(sink.steps.back(), report.steps);
  EXPECT_EQ(mass.back(), report.value);
  int rows_checked = 0;
  for (std::size_t k = 0; k + 1 < mass.size(); ++k)
    if (!std::isnan(mass[k])) {
      EXPECT_LE(mass[k], 6.0) << "step " << sink.steps[k];
      ++rows_checked;
    }
  EXPECT_GT(rows_checked, 10);
}

TEST(Stages, BadStagesNameTheKey) {
  const auto expect_error = [](const std::string& stages, const std::string& needle) {
    try {
      (void)basalt::test::scene_from(pile_scene("dt = 2e-3") + stages);
      ADD_FAILURE() << "no error for " << stages;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error("[[stages]]\nsteps = 10\nremove_walls = [\"gate\"]\n", "stages[0].remove_walls");
  expect_error("[[stages]]\nsteps = 10\nremove_walls = [\"gate\"]\n", "floor, piston");
  expect_error("[[stages]]\nuntil = { kinetic_energy_below = 1.0 }\n", "needs steps");
  expect_error("[[stages]]\nsteps = 5\nuntil = { every = 3 }\n", "give one condition");
  expect_error("[[stages]]\nsteps = 5\nuntil = { time_above = 1.0, kinetic_energy_below = 1.0 }\n",
               "give one condition");
  expect_error("[[stages]]\nsteps = 5\nuntil = { wall_force = \"piston\" }\n", "above = X or below");
  expect_error("[[stages]]\nsteps = 5\nwall_velocity = { nope = [0.0, 0.0, 1.0] }\n",
               "no planar wall named \"nope\"");
  expect_error("[[stages]]\nsteps = 5\nspeed = 3\n", "speed");
  expect_error("[[stages]]\nsteps = 5\nuntil = { saver = \"mass_below\", above = 1.0 }\n",
               "no field saver writes a column \"mass_below\"");
  const std::string saver = "[[output.fields]]\ntype = \"mass_below\"\nz = 0.0\nevery = 10\n";
  expect_error(saver + "[[stages]]\nsteps = 5\nuntil = { saver = \"mass_below\" }\n", "above = X or below");
  expect_error(saver + "[[stages]]\nsteps = 5\nuntil = { saver = \"mass_below\", below = 1.0, every = 15 }\n",
               "multiple of the saver's every = 10");
}

TEST(Steering, AContactGroupTakesNewParametersAndRefusesAnUnstableOne) {
  // set_contact: a linear elastic pile (E = K overlap^2 / 2 per contact) settles for a while; tripling K at
  // fixed positions triples the contact energy at once; a K that makes dt unstable is refused and leaves
  // the old K in place.
  std::string text = pile_scene("dt = 2e-3");
  const auto from = text.find("[[interactions]]"), to = text.find("[[walls]]");
  text.replace(from, to - from,
               "[[interactions]]\nname = \"grains\"\ntype = \"linear_elastic\"\nK = 1000.0\n");
  Simulation<double> sim(basalt::test::scene_from(text), pile(), MPI_COMM_WORLD, basalt::test::quiet());
  FieldRows rows(sim.comm(), nullptr);
  sim.run(300, rows);
  const double e1 = sim.energies()[2];
  ASSERT_GT(e1, 0.0);
  sim.set_contact("grains", "K = 3000.0");
  const double e3 = sim.energies()[2];
  EXPECT_NEAR(e3, 3 * e1, 1e-12 * e3);
  try {
    sim.set_contact("grains", "K = 1e9");
    ADD_FAILURE() << "an unstable K was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("interactions \"grains\""), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("critical time step"), std::string::npos) << e.what();
  }
  EXPECT_EQ(sim.energies()[2], e3);  // the K of before
  const auto expect_error = [&](const std::string& name, const std::string& keys, const std::string& needle) {
    try {
      sim.set_contact(name, keys);
      ADD_FAILURE() << "no error for " << name << ": " << keys;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error("sand", "K = 1.0", "contact groups: grains");
  expect_error("grains", "K = 1.0\nQ = 2.0", "Q");
  expect_error("grains", "K = -1.0", "K");
  sim.run(100, rows);  // and the run goes on with K = 3000
  EXPECT_TRUE(std::isfinite(sim.kinetic_energy()));
}

TEST(Steering, AWallAddedMidRunCatchesTheFallingPileAndOneBehindParticlesIsRefused) {
  // A stage takes the floor away and adds "catch" (active = false in the scene: the pile falls through it
  // until then) 0.5 below the floor; the pile comes to rest on it. Adding "deep" (facing up at z = 3, the
  // whole pile below it) is refused, naming a particle behind it.
  const auto scene = basalt::test::scene_from(pile_scene("dt = 2e-3") + R"(
[[walls]]
name = "catch"
point = [0.0, 0.0, -0.5]
normal = [0.0, 0.0, 1.0]
K = 1000.0
active = false
[[walls]]
name = "deep"
point = [0.0, 0.0, 3.0]
normal = [0.0, 0.0, 1.0]
K = 1000.0
active = false
[[body_forces]]
type = "linear_damping"
viscosity = 0.5
[[stages]]
name = "drop"
remove_walls = ["floor"]
steps = 400
[[stages]]
name = "catch"
add_walls = ["catch"]
steps = 4000
)");
  Simulation<double> sim(scene, pile(), MPI_COMM_WORLD, basalt::test::quiet());
  EXPECT_TRUE(sim.walls().removed(sim.wall_index("catch")));
  FieldRows rows(sim.comm(), nullptr);
  std::vector<double> lowest;
  run_stages(sim, rows, scene.stages,
             [&](const StageSpec&, const StageReport&) { lowest.push_back(lowest_z(sim)); });
  ASSERT_EQ(lowest.size(), 2u);
  EXPECT_LT(lowest[0], 0.3);  // fell below the floor's place, still above the catch (its centre)
  EXPECT_GT(lowest[0], -0.5);
  EXPECT_FALSE(sim.walls().removed(sim.wall_index("catch")));
  EXPECT_GT(lowest[1], -0.5);  // caught: resting on it, overlapping by a little
  EXPECT_LT(lowest[1], 0.0);
  double fz = sim.walls().force(sim.wall_index("catch"))[2];
  if (sim.comm().size() > 1) fz = sim.comm().sum(fz);
  EXPECT_LT(fz, 0.0);  // the pile's weight on it
  try {
    sim.add_wall("deep");
    ADD_FAILURE() << "a wall with particles behind it was added";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("wall \"deep\" cannot be added: 48 particle(s)"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(sim.walls().removed(sim.wall_index("deep")));
}

TEST(Steering, AMotionSetMidRunStartsItsClockThereAndAServoHoldsItsTarget) {
  // set_wall_motion: the piston (z = 10, facing down) moves at constant velocity from where it is, its
  // clock starting now (z = 10 - v (t - t0), not 10 - v t); then a servo set mid-run brings it onto the
  // damped pile and holds the compressive force at its target.
  const auto scene = basalt::test::scene_from(pile_scene("dt = 2e-3") + R"(
[[body_forces]]
type = "linear_damping"
viscosity = 1.0
)");
  Simulation<double> sim(scene, pile(), MPI_COMM_WORLD, basalt::test::quiet());
  FieldRows rows(sim.comm(), nullptr);
  const std::size_t piston = sim.wall_index("piston");
  sim.run(100, rows);
  sim.set_wall_motion("piston", "type = \"constant_velocity\"\nvelocity = [0.0, 0.0, -2.0]");
  sim.run(1000, rows);
  EXPECT_NEAR(sim.walls().point(piston)[2], 10.0 - 2.0 * 1000 * 2e-3, 1e-9);  // 6: above the pile (< 3)
  sim.set_wall_motion("piston", "type = \"servo\"\ntarget_force = 20.0\ngain = 0.02\nmax_speed = 1.0");
  sim.run(8000, rows);
  double fz = sim.walls().force(piston)[2];
  if (sim.comm().size() > 1) fz = sim.comm().sum(fz);
  EXPECT_NEAR(fz, 20.0, 0.5);  // the particles push it up (its normal is -z) with the target force
  EXPECT_LT(sim.walls().point(piston)[2], 3.5);
  try {
    sim.set_wall_motion("piston", "type = \"servo\"\ntarget_force = 20.0\ngain = 0.02");
    ADD_FAILURE() << "a servo without max_speed was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("max_speed"), std::string::npos) << e.what();
  }
}

TEST(Steering, GravityChangedMidRunMovesTheCentreOfMassByTheNewAcceleration) {
  // In free fall (the floor taken away) the contacts cancel in the momentum: the centre of mass's vertical
  // velocity changes by g t, with the new g from the step it is set.
  auto sim = make("dt = 2e-3");
  sim.run(50);
  sim.remove_wall("floor");
  sim.set_body_force("gravity0", "acceleration = [0.0, 0.0, -3.0]");
  const auto momentum = [&] {
    const auto& p = sim.particles();
    double m = 0, mv = 0;
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      m += p.mass(i);
      mv += p.mass(i) * p.vz[i];
    }
    if (sim.comm().size() > 1) {
      m = sim.comm().sum(m);
      mv = sim.comm().sum(mv);
    }
    return mv / m;
  };
  const double v0 = momentum();
  sim.run(100);
  EXPECT_NEAR(momentum() - v0, -3.0 * 100 * 2e-3, 1e-9);
  EXPECT_THROW(sim.set_body_force("nope", "acceleration = [0.0, 0.0, -1.0]"), InputError);
  try {
    sim.set_body_force("gravity0", "acceleration = [0.0, 0.0]");
    ADD_FAILURE() << "no error for a 2-vector";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("acceleration"), std::string::npos) << e.what();
  }
  try {
    sim.set_body_force("gravity0", "acceleration = [0.0, 0.0, -1.0]\nspeed = 2");
    ADD_FAILURE() << "no error for an unknown key";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("speed"), std::string::npos) << e.what();
  }
}
