// The wave benchmark on cube1.geo gives the same kinetic-energy series on any number of ranks and any
// rank grid, to 1e-9 relative: a serial run on rank 0 is the reference for runs over all ranks.
#include <gtest/gtest.h>
#include <mpi.h>

#include <array>
#include <cmath>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;

namespace {

constexpr int kSteps = 400;  // past the first rebuild with migration (step ~323)

std::vector<double> ke_series(const Scene& scene, const basalt::io::Geometry& g, MPI_Comm comm,
                              std::array<int, 3> dims) {
  return basalt::test::run_fields(scene, g, comm, kSteps, dims).column(0);
}

}  // namespace

TEST(DecompositionInvariance, WaveKineticEnergyMatchesSerialRun) {
  const auto scene = parse_scene(basalt::test::source_dir() / "scenes" / "wave.toml");
  const auto g = basalt::test::cube1();
  const int n = basalt::test::size();
  std::vector<double> ref(kSteps);
  if (basalt::test::rank() == 0) ref = ke_series(scene, g, MPI_COMM_SELF, {1, 1, 1});
  MPI_Bcast(ref.data(), kSteps, MPI_DOUBLE, 0, basalt::test::world());
  ASSERT_GT(ref.back(), 1.0) << "the pulse must have put energy in";

  std::vector<std::array<int, 3>> grids{{0, 0, 0}};
  if (n == 2) grids.insert(grids.end(), {{1, 1, 2}, {1, 2, 1}});
  if (n == 4) grids.insert(grids.end(), {{4, 1, 1}, {1, 2, 2}, {1, 1, 4}});
  if (n == 8) grids.insert(grids.end(), {{1, 2, 4}, {4, 2, 1}});
  for (const auto& dims : grids) {
    const auto ke = ke_series(scene, g, basalt::test::world(), dims);
    if (basalt::test::rank() != 0) continue;
    ASSERT_EQ(ke.size(), ref.size());
    double worst = 0;
    std::size_t at = 0;
    for (std::size_t k = 0; k < ke.size(); ++k) {
      if (ref[k] < 1e-9 * ref.back()) continue;  // the first steps: KE ~ 1e-11, pure rounding
      const double rel = std::abs(ke[k] - ref[k]) / ref[k];
      if (rel > worst) {
        worst = rel;
        at = k + 1;
      }
    }
    EXPECT_LT(worst, 1e-9) << "dims " << dims[0] << "," << dims[1] << "," << dims[2] << ": worst at step "
                           << at;
    std::printf("np %d dims %d,%d,%d: max relative KE difference %.3g\n", n, dims[0], dims[1], dims[2],
                worst);
  }
}

TEST(DecompositionInvariance, TooThinRegionsAreRefused) {
  if (basalt::test::size() < 8) GTEST_SKIP() << "needs 8 ranks";
  const auto scene = parse_scene(basalt::test::source_dir() / "scenes" / "wave.toml");
  const auto g = basalt::test::cube1();
  RunOptions opt;
  opt.dims = {1, 1, 8};  // 15 mm / 8 = 1.875 mm, thinner than the ghost width 2 rmax + skin = 2.1 mm
  try {
    Simulation<double> sim(scene, g, basalt::test::world(), opt);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ghost width"), std::string::npos) << e.what();
  }
}
