// The rotational step limit (docs/stability.md, "The rotational step limit"): a tangential spring acts at
// the contact point, which a rotating solid sphere makes lighter (compliance 1/m + r^2/I = 3.5/m), so the
// critical step of a frictional contact between rotating spheres is 2 / sqrt(7 ks / m) (two spheres) or
// 2 / sqrt(3.5 ks / m) (a sphere on a wall), below the translational 2 / sqrt(2 k / m). Checked against
// those closed forms, and by running a sphere on a frictional floor just below and just above the limit.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;
using basalt::io::Geometry;
using basalt::test::mass_of;

namespace {

/// Two spheres (r = 0.5 and 1) far apart: the critical step is that of a contact that forms later.
double apart_critical_step(const std::string& pair_model, double ks, bool rotation,
                           const std::string& extra = "") {
  const std::string body = "[particles]\nrotation = " + std::string(rotation ? "true" : "false") +
                           "\n[run]\ndt = 1e-4\nsteps = 0\nskin = 0.05\n[[interactions]]\ntype = \"" +
                           pair_model + "\"\nK = 1000.0\nKs = " + std::to_string(ks) + "\nmu = 0.5\n" + extra;
  Geometry g;
  g.add_particle(1, {0, 0, 0}, 0.5);
  g.add_particle(2, {3, 0, 0}, 1.0);
  g.sort_by_id();
  Simulation<double> sim(basalt::test::scene_from(body), g, MPI_COMM_SELF);
  return sim.stability().dt_critical;
}

}  // namespace

TEST(RotationalLimit, TwoRotatingSpheresStuckTogetherAt7KsOverM) {
  const double m = mass_of(0.5);
  EXPECT_NEAR(apart_critical_step("rot_friction", 1000, true), 2 / std::sqrt(7 * 1000 / m), 1e-12);
  EXPECT_NEAR(apart_critical_step("rolling_friction", 1000, true, "mu_roll = 0.1\n"),
              2 / std::sqrt(7 * 1000 / m), 1e-12);
  // A soft shear spring (7 ks < 2 K) leaves the normal spring's limit.
  EXPECT_NEAR(apart_critical_step("rot_friction", 200, true), 2 / std::sqrt(2 * 1000 / m), 1e-12);
  // ESyS's NRotFriction: the shear force pulls the centres only, as the normal spring does.
  EXPECT_NEAR(apart_critical_step("friction", 1000, true), 2 / std::sqrt(2 * 1000 / m), 1e-12);
  EXPECT_NEAR(apart_critical_step("friction", 1000, false), 2 / std::sqrt(2 * 1000 / m), 1e-12);
}

namespace {

/// A sphere (r = 0.5) resting under gravity 1 on a frictional floor (K = Ks = 1000, mu = 10: it sticks),
/// spun by 1e-3 about x; dt = `fraction` of the critical step, forced above it. Returns the largest spin
/// over 2,000 steps (it stays 1e-3 where the step is stable).
double largest_spin(double fraction) {
  const std::string body = R"([particles]
rotation = true
[run]
dt_fraction = )" + std::to_string(fraction) +
                           R"(
force_dt = true
steps = 2000
skin = 0.05
[[interactions]]
type = "linear_elastic"
K = 1000.0
[[walls]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
interaction = "friction"
K = 1000.0
Ks = 1000.0
mu = 10.0
[[body_forces]]
type = "gravity"
acceleration = [0.0, 0.0, -1.0]
)";
  const double r = 0.5, m = mass_of(r);
  Geometry g;
  g.add_particle(1, {0, 0, r - m / 1000}, r);  // at the static overlap m g / K
  Simulation<double> sim(basalt::test::scene_from(body), g, MPI_COMM_SELF);
  EXPECT_NEAR(sim.stability().dt_critical, 2 / std::sqrt(3.5 * 1000 / m), 1e-12)
      << "the sphere on the wall: omega^2 = 3.5 Ks / m, above K / m";
  sim.particles().wx[0] = 1e-3;
  sim.state_changed();
  double spin = 0;
  for (int s = 0; s < 2000; ++s) {
    sim.step();
    const auto& p = sim.particles();
    spin = std::max(spin, std::hypot(double(p.wx[0]), double(p.wy[0]), double(p.wz[0])));
    if (!std::isfinite(spin)) break;
  }
  return spin;
}

}  // namespace

TEST(RotationalLimit, SphereOnAFrictionalFloorStableBelowUnstableAbove) {
  EXPECT_LT(largest_spin(0.95), 1.5e-3) << "stable at 0.95 of the critical step";
  EXPECT_GT(largest_spin(1.05), 1e-2) << "the tangential mode grows at 1.05 of it";
}
