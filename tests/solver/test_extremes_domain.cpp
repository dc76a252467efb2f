// Stability at the extremes of the decomposition (docs/stability.md, issue 13), at np 1, 2, 4 and 8
// (oversubscribed): a bonded block that drifts until every particle is in one rank's region (the other
// ranks empty), and a particle that flies 1e6 length units away from its block. Nothing is lost (every
// id owned by exactly one rank), and each run agrees with the serial run on rank 0.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/simulation.hpp"
#include "extremes_helpers.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;
using basalt::io::Geometry;

namespace {

struct Trace {
  std::vector<double> ke;         // every `every` steps
  basalt::test::GlobalState end;  // the final state by id
  int ranks_with_particles = 0;   // at the end
  std::int64_t total = 0;         // particles at the end
};

template <class Real>
Trace trace(const Scene& scene, const Geometry& g, MPI_Comm comm, std::array<double, 3> drift,
            std::int64_t first_id, std::size_t n_ids, int blocks, std::int64_t every, std::int64_t flyer = -1,
            std::array<double, 3> flyer_v = {0, 0, 0}) {
  const auto opt = basalt::test::quiet();
  Simulation<Real> sim(scene, g, comm, opt);
  auto& p = sim.particles();
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const auto id = static_cast<std::uint64_t>(p.id[i]);
    std::array<double, 3> v = drift;
    if (p.id[i] == flyer) v = flyer_v;
    p.vx[i] = Real(v[0] + 0.02 * basalt::test::hash_unit(3 * id));
    p.vy[i] = Real(v[1] + 0.02 * basalt::test::hash_unit(3 * id + 1));
    p.vz[i] = Real(v[2] + 0.02 * basalt::test::hash_unit(3 * id + 2));
  }
  sim.state_changed();
  Trace t;
  for (int b = 0; b < blocks; ++b) {
    sim.run(every);
    t.ke.push_back(sim.kinetic_energy());
  }
  t.end = basalt::test::gather_state(sim, first_id, n_ids);
  const bool mine = sim.particles().n_owned > 0;
  int any = mine ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_SUM, comm);
  t.ranks_with_particles = any;
  t.total = sim.comm().sum(static_cast<long long>(sim.particles().n_owned));
  return t;
}

/// The serial run on rank 0, broadcast: KE series and final positions.
void broadcast(Trace& t, std::size_t n, std::size_t blocks) {
  std::vector<double> buf(t.ke);
  buf.resize(blocks);
  MPI_Bcast(buf.data(), static_cast<int>(buf.size()), MPI_DOUBLE, 0, basalt::test::world());
  t.ke = buf;
  std::vector<double> x(3 * n);
  if (basalt::test::rank() == 0)
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t c = 0; c < 3; ++c) x[3 * k + c] = t.end.x[k][c];
  MPI_Bcast(x.data(), static_cast<int>(x.size()), MPI_DOUBLE, 0, basalt::test::world());
  t.end.x.resize(n);
  t.end.seen.assign(n, 1);
  for (std::size_t k = 0; k < n; ++k) t.end.x[k] = {x[3 * k], x[3 * k + 1], x[3 * k + 2]};
}

double max_relative(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0;
  for (std::size_t k = 0; k < a.size(); ++k) worst = std::max(worst, std::abs(a[k] - b[k]) / std::abs(b[k]));
  return worst;
}

const std::string kBlockScene = R"([run]
dt = 1e-3
steps = 0
skin = 0.1
[[interactions]]
type = "linear_bond"
K = 1000.0
[[interactions]]
type = "linear_elastic"
K = 1000.0
)";

}  // namespace

// A bonded block of cube1.geo (0-3.2 mm) drifting at (8, 8, 8) mm/ms for 500 steps: it leaves its initial
// box (the decomposition's) and ends wholly in the region of the rank at the grid's far corner, every
// other rank empty. The kinetic energy every 25 steps and the final positions agree with the serial run
// to 1e-9 (rounding: forces are summed in another order on several ranks).
TEST(ExtremesDomain, BlockDriftsIntoOneSubdomain) {
  static const Geometry block = [] {
    const auto full = basalt::test::cube1();
    return basalt::test::sub_cube(full, 0.0, 3.2);
  }();
  const auto scene = basalt::test::scene_from(kBlockScene);
  const std::int64_t first = block.id.front();
  const std::size_t n = static_cast<std::size_t>(block.id.back() - first + 1);
  Trace ref;
  if (basalt::test::rank() == 0)
    ref = trace<double>(scene, block, MPI_COMM_SELF, {8, 8, 8}, first, n, 20, 25);
  broadcast(ref, n, 20);
  const auto t = trace<double>(scene, block, basalt::test::world(), {8, 8, 8}, first, n, 20, 25);
  EXPECT_EQ(t.total, static_cast<std::int64_t>(block.size()));
  std::size_t owned = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (t.end.seen[k] == 0) continue;  // ids absent from the sub-block
    EXPECT_EQ(t.end.seen[k], 1) << "id " << first + std::int64_t(k);
    ++owned;
    for (std::size_t c = 0; c < 3; ++c)
      EXPECT_NEAR(t.end.x[k][c], ref.end.x[k][c], 1e-9 * (1 + std::abs(ref.end.x[k][c])));
    EXPECT_GT(t.end.x[k][0] - block.position[std::size_t(block.index_of(first + std::int64_t(k)))][0], 3.5);
  }
  EXPECT_EQ(owned, block.size());
  EXPECT_EQ(t.ranks_with_particles, 1) << "every particle in one rank's region";
  const double d = max_relative(t.ke, ref.ke);
  EXPECT_LT(d, 1e-9);
  if (basalt::test::rank() == 0)
    std::printf("np %d: %zu particles end on %d rank(s); KE vs serial max relative %.3g\n",
                basalt::test::size(), block.size(), t.ranks_with_particles, d);
}

// A 3 x 3 x 3 bonded block of spheres of radius 500 and one more sphere beside it, launched at 1950
// length/time (0.39 radii per step, below the blow-up limit of 0.5) for 5,200 steps of dt 0.1: it flies
// 1.0e6 length units (2,000 radii, 330 block widths) away. (A flight of 1e6 radii needs 2.6e6 steps: not a
// unit test; what matters to the domain is the distance against the block's size.) The domain follows (outer
// regions are open), the particle is never lost, its position is x0 + v t, and every rank count gives the
// serial run's kinetic energies and positions. Float keeps every particle too, its position within the
// rounding of 5,200 drifts at |x| <= 1e6 (ulp 0.0625). At np 8 (oversubscribed, ~3 ms a step) double only.
namespace {

Geometry block_and_flyer() {
  Geometry g;
  const double r = 500, s = 2 * r;
  std::int64_t id = 1;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) g.add_particle(id++, {i * s, j * s, k * s}, r);
  for (std::int64_t a = 1; a < id; ++a)
    for (std::int64_t b = a + 1; b < id; ++b) {
      const auto& xa = g.position[std::size_t(a - 1)];
      const auto& xb = g.position[std::size_t(b - 1)];
      if (std::hypot(xa[0] - xb[0], xa[1] - xb[1], xa[2] - xb[2]) < 1.5 * s) g.add_bond(a, b);
    }
  g.add_particle(id, {3 * s + 10, s, s}, r);  // 28: beside the block, 10 apart
  g.sort_by_id();
  return g;
}

const std::string kFlyerScene = R"([run]
dt = 0.1
steps = 0
skin = 2000.0
[[interactions]]
type = "linear_bond"
K = 1000.0
[[interactions]]
type = "linear_elastic"
K = 1000.0
)";

template <class Real>
void flyer_case(double tol_x) {
  const auto g = block_and_flyer();
  const auto scene = basalt::test::scene_from(kFlyerScene);
  const std::array<double, 3> v{1950.0, 0, 0};
  const int blocks = 26;
  const std::int64_t every = 200;
  Trace ref;
  if (basalt::test::rank() == 0)
    ref = trace<Real>(scene, g, MPI_COMM_SELF, {0, 0, 0}, 1, g.size(), blocks, every, 28, v);
  broadcast(ref, g.size(), blocks);
  const auto t = trace<Real>(scene, g, basalt::test::world(), {0, 0, 0}, 1, g.size(), blocks, every, 28, v);
  EXPECT_EQ(t.total, 28);
  for (std::size_t k = 0; k < g.size(); ++k) EXPECT_EQ(t.end.seen[k], 1) << "id " << k + 1;
  const double time = 0.1 * blocks * every;
  const auto& xf = t.end.x[27];
  const double vx = v[0] + 0.02 * basalt::test::hash_unit(3 * 28);
  const double expect = g.position[27][0] + Real(vx) * time;
  EXPECT_GT(xf[0], 1e6);
  EXPECT_NEAR(xf[0], expect, tol_x) << "free flight";
  double dx = 0;
  for (std::size_t k = 0; k < g.size(); ++k)
    for (std::size_t c = 0; c < 3; ++c)
      dx = std::max(dx, std::abs(t.end.x[k][c] - ref.end.x[k][c]) / (1 + std::abs(ref.end.x[k][c])));
  const double dke = max_relative(t.ke, ref.ke);
  if (basalt::test::rank() == 0)
    std::printf("%s np %d: particle 28 at x = %.10g (x0 + v t = %.10g); vs serial: positions %.3g, KE %.3g\n",
                sizeof(Real) == 8 ? "double" : "float", basalt::test::size(), xf[0], expect, dx, dke);
  EXPECT_LT(dx, sizeof(Real) == 8 ? 1e-9 : 1e-3);  // float measured 6.8e-5
  EXPECT_LT(dke, sizeof(Real) == 8 ? 1e-9 : 1e-4);
}

}  // namespace

TEST(ExtremesDomain, ParticleFliesAMillionUnitsAway) {
  if (basalt::test::size() > 4) GTEST_SKIP() << "np 1, 2, 4 (5,200 steps at ~3 ms a step oversubscribed)";
  flyer_case<double>(1e-6);
}
TEST(ExtremesDomain, ParticleFliesAMillionUnitsAwayFloat) {
  if (basalt::test::size() > 4) GTEST_SKIP() << "np 1, 2, 4 (time)";
  flyer_case<float>(5200 * 0.0625);
}

// One particle on every rank count: the other ranks own nothing for the whole run, and it keeps its
// kinetic energy exactly while it crosses the cut planes (its box is a point: the planes pass through it).
TEST(ExtremesDomain, OneParticleOnManyRanks) {
  Geometry g;
  g.add_particle(3, {1, 2, 3}, 0.5);
  const auto opt = basalt::test::quiet();
  Simulation<double> sim(basalt::test::scene_from(kBlockScene), g, basalt::test::world(), opt);
  auto& p = sim.particles();
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    p.vx[i] = -0.5;
    p.vy[i] = 0.25;
    p.vz[i] = -1.0;
  }
  sim.state_changed();
  const double ke0 = sim.kinetic_energy();
  EXPECT_GT(ke0, 0.0);
  sim.run(500);
  EXPECT_EQ(sim.kinetic_energy(), ke0);
  EXPECT_GE(sim.rebuilds(), 8);
  const auto s = basalt::test::gather_state(sim, 3, 1);
  EXPECT_EQ(s.seen[0], 1);
  EXPECT_NEAR(s.x[0][0], 1 - 0.5 * sim.time(), 1e-12);
  EXPECT_NEAR(s.x[0][2], 3 - 1.0 * sim.time(), 1e-12);
}

// Empty subdomains that would be thinner than the ghost width (a rank grid of 4 or 8 along one axis over one
// particle) are refused, naming the region's width, the ghost width and the grid.
TEST(ExtremesDomain, RegionsThinnerThanTheGhostWidthAreRefused) {
  if (basalt::test::size() < 4) GTEST_SKIP() << "needs 3 or more ranks along an axis";
  Geometry g;
  g.add_particle(3, {1, 2, 3}, 0.5);
  const auto opt = basalt::test::quiet({basalt::test::size(), 1, 1});
  std::string msg;
  try {
    Simulation<double> sim(basalt::test::scene_from(kBlockScene), g, basalt::test::world(), opt);
  } catch (const InputError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("too many ranks for this geometry"), std::string::npos) << msg;
  EXPECT_NE(msg.find("less than the ghost width 1.1"), std::string::npos) << msg;
  EXPECT_NE(msg.find(std::to_string(basalt::test::size()) + "x1x1"), std::string::npos) << msg;
}
