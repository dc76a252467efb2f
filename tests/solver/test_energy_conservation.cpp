// Velocity Verlet on a bonded block with no wall motion: the total energy oscillates boundedly and
// does not drift over 10,000 steps.
#include <gtest/gtest.h>

#include <cmath>

#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;

TEST(EnergyConservation, BondedBlockOver10000Steps) {
  const auto full = basalt::test::cube1();
  const auto g = basalt::test::sub_cube(full, 0.0, 5.0);
  ASSERT_GT(g.size(), 200u);
  const auto scene = basalt::test::scene_from(R"(
[run]
dt = 1e-3
steps = 10000
skin = 0.05
energy_check_every = 0
[[interactions]]
type = "linear_bond"
K = 1000.0
[[interactions]]
type = "linear_elastic"
K = 1000.0
)");
  Simulation<double> sim(scene, g, MPI_COMM_SELF);
  basalt::test::random_velocities(sim, 0.05);
  auto total = [&] {
    const auto e = sim.energies();
    return e[0] + e[1] + e[2] + e[3];
  };
  const double e0 = total();
  ASSERT_GT(e0, 0);
  std::vector<double> series;
  double worst = 0;
  for (int block = 0; block < 100; ++block) {
    sim.run(100);
    const double e = total();
    series.push_back(e);
    worst = std::max(worst, std::abs(e - e0) / e0);
  }
  // Kinetic energy was exchanged with the bonds (the test is not vacuous) ...
  const auto parts = sim.energies();
  EXPECT_GT(parts[1], 0.1 * e0);
  // ... the total stayed within a bounded oscillation ...
  EXPECT_LT(worst, 2e-3) << "largest relative energy error";
  // ... and did not drift: the last fifth averages like the first fifth.
  double first = 0, last = 0;
  for (int k = 0; k < 20; ++k) {
    first += series[static_cast<std::size_t>(k)] / 20;
    last += series[series.size() - 1 - static_cast<std::size_t>(k)] / 20;
  }
  EXPECT_LT(std::abs(last - first) / e0, 2e-4) << "energy drift";
  std::printf("relative energy error: max %.3g, drift %.3g (%zu particles)\n", worst, (last - first) / e0,
              g.size());
}
