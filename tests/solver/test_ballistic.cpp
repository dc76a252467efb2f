// Issue 48: a particle in free flight is physics, not a blow-up (docs/stability.md, "Blow-up check"). A
// particle moving 10 radii per step away from everything runs to the end with the trajectory x0 + v t, on 1
// and 2 ranks (crossing the ranks' regions, however far it goes per step); one fast enough to pass
// through a neighbour or a wall within a step still stops the run, saying which.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/simulation.hpp"
#include "extremes_helpers.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;
using basalt::io::Geometry;

namespace {

constexpr double kR = 0.5;

/// A bonded 4 x 4 x 4 block of spheres of radius 0.5 (spacing 1) in [0, 3]^3, and particle 65 at `at`
/// (by default beside the block at x = 5, a gap of 1).
Geometry block_and_projectile(const std::array<double, 3>& at = {5.0, 1.5, 1.5}) {
  Geometry g;
  std::int64_t id = 1;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) g.add_particle(id++, {double(i), double(j), double(k)}, kR);
  for (std::int64_t a = 1; a < id; ++a)
    for (std::int64_t b = a + 1; b < id; ++b) {
      const auto& xa = g.position[std::size_t(a - 1)];
      const auto& xb = g.position[std::size_t(b - 1)];
      if (std::hypot(xa[0] - xb[0], xa[1] - xb[1], xa[2] - xb[2]) < 1.01) g.add_bond(a, b);
    }
  g.add_particle(id, at, kR);
  g.sort_by_id();
  return g;
}

const std::string kScene = R"([run]
dt = 0.01
steps = 0
skin = 0.2
[[interactions]]
type = "linear_bond"
K = 100.0
[[interactions]]
type = "linear_elastic"
K = 100.0
)";

/// Runs `steps` with particle 65's velocity set to v (the block at rest); returns the message of the
/// error that stopped it, or "" when it ran to the end (then `end` holds every particle's state).
std::string fly(const Scene& scene, const std::array<double, 3>& v, std::int64_t steps,
                basalt::test::GlobalState* end = nullptr, const std::array<double, 3>& at = {5.0, 1.5, 1.5}) {
  const auto opt = basalt::test::quiet();
  const auto g = block_and_projectile(at);
  Simulation<double> sim(scene, g, basalt::test::world(), opt);
  auto& p = sim.particles();
  for (std::size_t i = 0; i < p.n_owned; ++i)
    if (p.id[i] == 65) {
      p.vx[i] = v[0];
      p.vy[i] = v[1];
      p.vz[i] = v[2];
    }
  sim.state_changed();
  try {
    sim.run(steps);
  } catch (const RunError& e) {
    return e.what();
  }
  if (end) *end = basalt::test::gather_state(sim, 1, g.size());
  return "";
}

}  // namespace

// 10 radii (5 length units) per step along +x, away from the block: 400 steps take it 2,000 units away.
// Before, the blow-up check stopped it at step 1 ("moved too far in one step").
TEST(Ballistic, LoneParticleAtTenRadiiPerStepRunsToTheEnd) {
  const auto scene = basalt::test::scene_from(kScene);
  const double vx = 10 * kR / 0.01;
  basalt::test::GlobalState end;
  const auto msg = fly(scene, {vx, 0, 0}, 400, &end);
  ASSERT_EQ(msg, "") << msg;
  for (std::size_t k = 0; k < end.seen.size(); ++k) EXPECT_EQ(end.seen[k], 1) << "id " << k + 1;
  // x += v dt, 400 times: exact but for the rounding of each sum (|x| <= 2005, ulp 2.3e-13).
  EXPECT_NEAR(end.x[64][0], 5.0 + vx * 0.01 * 400, 1e-9);
  EXPECT_EQ(end.x[64][1], 1.5);
  EXPECT_EQ(end.x[64][2], 1.5);
  EXPECT_EQ(end.v[64][0], vx);
  for (std::size_t k = 0; k < 64; ++k) EXPECT_LT(std::abs(end.v[k][0]), 1e-12) << "the block stays at rest";
}

// Passing the block at a distance (y = 6, the block's particles reach y = 3.5) along -x at 10 radii per step:
// at np 2 and 4 it leaves the region of the rank that owned it in its first step and crosses the others'.
TEST(Ballistic, ParticlePassingTheBlockAcrossTheRanksRunsToTheEnd) {
  const auto scene = basalt::test::scene_from(kScene);
  const double vx = -10 * kR / 0.01;
  basalt::test::GlobalState end;
  const auto msg = fly(scene, {vx, 0, 0}, 400, &end, {5.0, 6.0, 1.5});
  ASSERT_EQ(msg, "") << msg;
  for (std::size_t k = 0; k < end.seen.size(); ++k) EXPECT_EQ(end.seen[k], 1) << "id " << k + 1;
  EXPECT_NEAR(end.x[64][0], 5.0 + vx * 0.01 * 400, 1e-9);
  EXPECT_EQ(end.x[64][1], 6.0);
  EXPECT_EQ(end.v[64][0], vx);
}

// The same particle aimed at the block at 10 radii per step: its first step from x = 5 to 0 passes through
// particles of the block's face x = 3. The run stops at that step, naming the particle met.
TEST(Ballistic, ParticleThatWouldPassThroughAnotherStops) {
  const auto scene = basalt::test::scene_from(kScene);
  const auto msg = fly(scene, {-10 * kR / 0.01, 0, 0}, 10);
  if (basalt::test::rank() == 0) std::printf("%s\n", msg.c_str());
  EXPECT_NE(msg.find("step 1: blow-up: particle id 65 moved too far in one step"), std::string::npos) << msg;
  EXPECT_NE(msg.find("could pass through it"), std::string::npos) << msg;
  EXPECT_NE(msg.find("of particle id "), std::string::npos) << msg;
}

// Away from the block but towards a wall at x = 20: 3 steps of 5 are clear (x = 20 reached at step 3 and a
// sphere of radius 0.5 touches the wall from x = 19.5), the step from 15 to 20 meets it.
TEST(Ballistic, ParticleThatWouldPassThroughAWallStops) {
  const auto scene = basalt::test::scene_from(kScene + R"(
[[walls]]
name = "far"
point = [20.0, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
K = 100.0
)");
  const auto msg = fly(scene, {10 * kR / 0.01, 0, 0}, 10);
  if (basalt::test::rank() == 0) std::printf("%s\n", msg.c_str());
  EXPECT_NE(msg.find("step 3: blow-up: particle id 65 moved too far in one step"), std::string::npos) << msg;
  EXPECT_NE(msg.find("of wall \"far\""), std::string::npos) << msg;
  EXPECT_NE(msg.find("could pass through the wall"), std::string::npos) << msg;
}
