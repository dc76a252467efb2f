// run.precision = "mixed" (scene/frame_origin.hpp, docs/stability.md "Mixed precision"): float storage and
// kernels with positions held as float offsets from a double origin at the geometry's centre, and a
// compensated (Kahan) drift. The frame, the drift's remainders, offset independence, and the wave's
// kinetic energy on any number of ranks.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "basalt/io/frame.hpp"
#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/integrate/integrators.hpp"
#include "basalt/solver/output/simulation_frame.hpp"
#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;
using basalt::io::Geometry;

namespace {

Scene wave_scene(double d = 0, const std::string& precision = "mixed") {
  Scene scene = parse_scene(basalt::test::source_dir() / "scenes" / "wave.toml");
  for (auto& w : scene.walls)
    for (auto& c : w.point) c += d;
  scene.precision = precision;
  return scene;
}

using basalt::test::cube1;

Geometry shifted(const Geometry& g, double d) {
  Geometry s = g;
  for (auto& x : s.position)
    for (auto& c : x) c += d;
  return s;
}

template <class Real>
std::vector<double> ke_series(const Scene& scene, const Geometry& g, MPI_Comm comm, int steps,
                              std::array<int, 3> dims = {0, 0, 0}) {
  return basalt::test::run_fields<Real>(scene, g, comm, steps, dims).column(0);
}

/// max |a - b| / max |b|
double max_rel(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0, peak = 0;
  for (std::size_t k = 0; k < b.size(); ++k) {
    worst = std::max(worst, std::abs(a[k] - b[k]));
    peak = std::max(peak, std::abs(b[k]));
  }
  return worst / peak;
}

}  // namespace

// Positions live as float offsets from the centre of the geometry's box; the wall is moved into the same
// frame; origin + offset gives back the geometry's coordinates to float rounding of the offsets (1e6 + a
// float offset of up to 8 mm: a few 1e-7), where plain float would round them to 0.06.
TEST(MixedPrecision, PositionsAreOffsetsFromTheCentre) {
  constexpr double d = 1e6;
  const auto opt = basalt::test::quiet();
  const Geometry g = shifted(cube1(), d);
  Simulation<float> sim(wave_scene(d), g, basalt::test::world(), opt);
  const auto& o = sim.origin();
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(o[k], d + 7.5, 0.5) << "axis " << k;
  EXPECT_EQ(std::string(sim.precision_name()), "mixed");
  const auto& p = sim.particles();
  double worst = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const auto& x = g.position[static_cast<std::size_t>(g.index_of(p.id[i]))];
    worst = std::max({worst, std::abs(o[0] + double(p.x[i]) - x[0]), std::abs(o[1] + double(p.y[i]) - x[1]),
                      std::abs(o[2] + double(p.z[i]) - x[2])});
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_NEAR(sim.walls().point(0)[2], d - o[2], 1e-9) << "the wall is in the frame";
  EXPECT_TRUE(p.with_compensation);
  EXPECT_EQ(p.cx.size(), p.n_owned);
  EXPECT_EQ(sim.restart_layout().origin, o);
}

// The compensated drift keeps increments far below an ulp of x: at x = 1000 (float ulp 6.1e-5) a particle
// moving 1e-6 per step moves 1e-3 in 1,000 steps, where the plain float drift leaves it where it was.
TEST(MixedPrecision, CompensatedDriftKeepsSmallIncrements) {
  for (const bool compensated : {false, true}) {
    Particles<float> p;
    p.with_compensation = compensated;
    p.push_owned(1, 1000.0f, 0.0f, 0.0f, 1.0f, 0, 1.0f, 1e-3f, 0.0f, 0.0f);
    for (int s = 0; s < 1000; ++s) kick_zero_drift(p, 0.0f, 1e-3f);
    const double moved = double(p.x[0]) - (compensated ? double(p.cx[0]) : 0.0) - 1000.0;
    if (compensated)
      EXPECT_NEAR(moved, 1e-3, 1e-6);
    else
      EXPECT_EQ(moved, 0.0) << "the plain float drift was expected to lose these increments";
  }
}

// The wave on cube1 shifted by 1e6 gives the unshifted run's kinetic energy in mixed (measured: 1e-7 over
// 300 steps), and agrees with double (measured L2 ~1e-5); float is refused there (FloatFarFromOriginIsRefused
// in test_stability.cpp: already at 1e3).
TEST(MixedPrecision, OffsetDoesNotChangeTheRun) {
  constexpr int steps = 300;
  const auto at0 = ke_series<float>(wave_scene(0), cube1(), basalt::test::world(), steps);
  const auto far = ke_series<float>(wave_scene(1e6), shifted(cube1(), 1e6), basalt::test::world(), steps);
  const auto dbl = ke_series<double>(wave_scene(0, "double"), cube1(), basalt::test::world(), steps);
  if (basalt::test::rank() != 0) return;
  ASSERT_EQ(at0.size(), far.size());
  const double offset = max_rel(far, at0), vs_double = max_rel(at0, dbl);
  std::printf("mixed, offset 1e6 vs 0: KE max rel %.3g; mixed vs double %.3g\n", offset, vs_double);
  EXPECT_LT(offset, 1e-4);
  EXPECT_LT(vs_double, 1e-3);
  EXPECT_GT(vs_double, 0.0) << "mixed and double gave identical bits: the float path was not taken";
}

// The same kinetic-energy series on any number of ranks and rank grid: a serial mixed run on rank 0 is
// the reference (the summation order differs, so agreement is to float rounding grown over 400 steps).
TEST(MixedPrecision, WaveKineticEnergyMatchesSerialRun) {
  constexpr int steps = 400;  // past the first rebuild with migration
  const auto scene = wave_scene(1e6);
  const auto g = shifted(cube1(), 1e6);
  const int n = basalt::test::size();
  std::vector<double> ref(steps);
  if (basalt::test::rank() == 0) ref = ke_series<float>(scene, g, MPI_COMM_SELF, steps, {1, 1, 1});
  MPI_Bcast(ref.data(), steps, MPI_DOUBLE, 0, basalt::test::world());
  std::vector<std::array<int, 3>> grids{{0, 0, 0}};
  if (n == 2) grids.push_back({1, 1, 2});
  if (n == 4) grids.push_back({1, 2, 2});
  for (const auto& dims : grids) {
    const auto ke = ke_series<float>(scene, g, basalt::test::world(), steps, dims);
    if (basalt::test::rank() != 0) continue;
    const double rel = max_rel(ke, ref);
    std::printf("mixed, %d ranks (%dx%dx%d) vs serial: KE max rel %.3g\n", n, dims[0], dims[1], dims[2], rel);
    EXPECT_LT(rel, 1e-4);
  }
}

// The load check looks at the extent in mixed, not the offset: a geometry at 1e9 starts without a warning
// about rounded strains, while float is refused there.
TEST(MixedPrecision, FarGeometryIsNotRefused) {
  const auto opt = basalt::test::quiet();
  EXPECT_NO_THROW(Simulation<float>(wave_scene(1e9), shifted(cube1(), 1e9), basalt::test::world(), opt));
  EXPECT_THROW(Simulation<float>(wave_scene(1e9, "float"), shifted(cube1(), 1e9), basalt::test::world(), opt),
               InputError);
}

// A checkpoint frame (as the I/O ranks read it) holds absolute coordinates: positions and positions at the
// rebuild = origin + float offset, the wall's point; and the exact float offsets and the drift's
// remainders as particle fields, which a restart reads back.
TEST(MixedPrecision, FramesAreAbsoluteAndCarryTheExactOffsets) {
  constexpr double d = 1e6;
  const auto opt = basalt::test::quiet();
  Scene scene = wave_scene(d);
  scene.checkpoint_every = 100;  // positions at the rebuild are kept for checkpoints only
  Simulation<float> sim(scene, shifted(cube1(), d), basalt::test::world(), opt);
  sim.run(30);
  std::vector<std::byte> bytes;
  basalt::io::serialize(SimulationFrame<float>(sim, basalt::io::kFrameCheckpoint), bytes);
  const auto q = basalt::io::deserialize(bytes);
  const auto& p = sim.particles();
  const auto& o = sim.origin();
  ASSERT_EQ(q.size(), p.n_owned);
  ASSERT_EQ(q.position_at_rebuild.size(), p.n_owned);
  const auto field = [&](const std::string& name) -> const std::vector<double>* {
    for (const auto& [n, v] : q.fields)
      if (n == name) return &v;
    return nullptr;
  };
  const std::vector<double>* exact[6];
  for (std::size_t k = 0; k < 6; ++k) {
    exact[k] = field(kFramePositionFields[k]);
    ASSERT_NE(exact[k], nullptr) << kFramePositionFields[k];
  }
  ASSERT_NE(field("position_remainder_x"), nullptr);
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const float x[3] = {p.x[i], p.y[i], p.z[i]}, xr[3] = {p.xr[i], p.yr[i], p.zr[i]};
    for (std::size_t k = 0; k < 3; ++k)
      wrong += q.position[i][k] != o[k] + double(x[k]) ||
               q.position_at_rebuild[i][k] != o[k] + double(xr[k]) || (*exact[k])[i] != double(x[k]) ||
               (*exact[k + 3])[i] != double(xr[k]);
  }
  EXPECT_EQ(wrong, 0u);
  if (basalt::test::rank() == 0) {
    ASSERT_EQ(q.walls.size(), 1u);
    EXPECT_EQ(q.walls[0].position[0], d);
    EXPECT_NEAR(q.walls[0].position[2], d, 0.01);
    EXPECT_GT(q.walls[0].position[2], d) << "the pulse has moved the wall up";
  }
}
