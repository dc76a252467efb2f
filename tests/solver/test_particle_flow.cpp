// Particles entering and leaving a run (docs/scenes.md, "Insertion and deletion"; simulation_flow.cpp):
// inserted particles overlap nothing, get unique new ids, are the same set on any number of ranks, and the
// run goes on with them; deleted particles take their bonds along on every rank; the scene's events happen
// at their steps; bad requests are refused. On 1 and 2 ranks.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"

using namespace basalt::solver;

namespace {

/// A 4 x 4 x 3 lattice pile (radii 0.425-0.5) on a floor, under gravity, in a box 4 x 4 wide; `extra` is
/// appended to the scene.
std::string pile_scene(const std::string& extra = "") {
  return R"(
[particles]
rotation = true
[run]
dt = 2e-3
steps = 0
skin = 0.1
[[interactions]]
type = "rot_friction"
K = 1000.0
Ks = 500.0
mu = 0.5
[[walls]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
K = 1000.0
[[body_forces]]
type = "gravity"
acceleration = [0.0, 0.0, -1.0]
)" + extra;
}

basalt::io::Geometry pile() {
  basalt::test::Lattice l;
  l.n = {4, 4, 3};
  l.jitter = 0.05;
  return basalt::test::jittered_lattice(l, basalt::test::grain_radius, [](int) { return 0; });
}

/// id -> (x, y, z, radius, tag, vz) of every particle, gathered on every rank.
std::map<std::int64_t, std::vector<double>> state(const Simulation<double>& sim) {
  return basalt::test::gather_by_id(sim, [](const Particles<double>& p, std::size_t i) {
    return std::vector<double>{p.x[i], p.y[i], p.z[i], p.radius[i], double(p.tag[i]), p.vz[i]};
  });
}

/// The deepest overlap of a particle with an id above `first` (an inserted one) with any other in `s`,
/// relative to the smaller radius (0: none). (The pile's own grains touch: their lattice is jittered.)
double deepest_overlap(const std::map<std::int64_t, std::vector<double>>& s, std::int64_t first = 48) {
  double worst = 0;
  for (auto a = s.begin(); a != s.end(); ++a)
    for (auto b = std::next(a); b != s.end(); ++b) {
      if (b->first <= first) continue;  // (map order: b's id exceeds a's)
      const auto &p = a->second, &q = b->second;
      const double d = std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
      worst = std::max(worst, (p[3] + q[3] - d) / std::min(p[3], q[3]));
    }
  return worst;
}

InsertSpec feed(std::int64_t count, std::uint64_t seed = 3) {
  InsertSpec s;
  s.name = "feed";
  s.region.lo = {0.0, 0.0, 3.2};
  s.region.hi = {4.0, 4.0, 6.0};
  s.rmin = 0.3;
  s.rmax = 0.45;
  s.density = 1;
  s.count = count;
  s.velocity = {0, 0, -0.5};
  s.tag = 7;
  s.seed = seed;
  return s;
}

}  // namespace

TEST(ParticleFlow, InsertedParticlesOverlapNothingAndGetNewIds) {
  Simulation<double> sim(basalt::test::scene_from(pile_scene()), pile(), MPI_COMM_WORLD,
                         basalt::test::quiet());
  const auto before = state(sim);
  const auto n = sim.insert_particles(feed(40));
  EXPECT_GT(n, 10) << "the region had room for many";
  EXPECT_LE(n, 40);
  EXPECT_EQ(sim.total_particles(), 48 + n);
  const auto after = state(sim);
  ASSERT_EQ(after.size(), before.size() + std::size_t(n)) << "particles lost or doubled";
  EXPECT_LE(deepest_overlap(after), 0.0) << "an inserted particle overlaps another";
  // New ids follow the geometry's, one each; the newcomers carry the spec's tag, radius range, velocity
  // and lie inside the region.
  for (std::int64_t id = 49; id < 49 + n; ++id) {
    ASSERT_TRUE(after.count(id)) << "id " << id;
    const auto& p = after.at(id);
    EXPECT_EQ(p[4], 7);
    EXPECT_GE(p[3], 0.3);
    EXPECT_LE(p[3], 0.45);
    EXPECT_EQ(p[5], -0.5);
    EXPECT_GE(p[2] - p[3], 3.2);
    EXPECT_LE(p[2] + p[3], 6.0);
  }
  EXPECT_EQ(sim.next_particle_id(), 49 + n);
  // A second event at the same place finds it taken by the first's particles where they are.
  const auto m = sim.insert_particles(feed(40, 4));
  EXPECT_LE(deepest_overlap(state(sim)), 0.0);
  EXPECT_EQ(sim.total_particles(), 48 + n + m);
  // The run goes on with them: they fall onto the pile, nothing is lost, the energy guard holds.
  sim.run(300);
  EXPECT_EQ(static_cast<std::int64_t>(state(sim).size()), 48 + n + m);
  EXPECT_LT(deepest_overlap(state(sim)), 0.2);
}

TEST(ParticleFlow, TheInsertedSetDoesNotDependOnTheRanks) {
  // The same insertion on this communicator and on one rank alone: the same ids at the same places, to
  // the bit (candidates are drawn alike everywhere; the owner of a place decides, and all agree).
  const auto scene = basalt::test::scene_from(pile_scene());
  Simulation<double> all(scene, pile(), MPI_COMM_WORLD, basalt::test::quiet());
  Simulation<double> alone(scene, pile(), MPI_COMM_SELF, basalt::test::quiet());
  all.run(50);
  alone.run(50);
  all.insert_particles(feed(30));
  alone.insert_particles(feed(30));
  const auto a = state(all), b = state(alone);
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [id, s] : a) {
    if (id <= 48) continue;
    EXPECT_EQ(s, b.at(id)) << "inserted particle " << id;
  }
}

TEST(ParticleFlow, DeletionTakesTheParticlesAndTheirBondsOnEveryRank) {
  // A bonded block of GenGeo's cube (bonds cross the ranks' boundary on 2 ranks): removing a slab takes
  // every bond with an end in it, on both ranks, and the run goes on.
  const auto g = basalt::test::sub_cube(basalt::test::cube1(), 0.0, 5.0);
  const auto scene = basalt::test::scene_from(R"(
[run]
dt = 1e-3
steps = 0
skin = 0.1
[[interactions]]
type = "linear_bond"
K = 1000.0
[[interactions]]
type = "linear_elastic"
K = 1000.0
)");
  Simulation<double> sim(scene, g, MPI_COMM_WORLD, basalt::test::quiet());
  DeleteSpec d;
  d.region.lo = {-10, -10, -10};
  d.region.hi = {10, 10, 2.0};
  std::vector<std::int64_t> gone;
  for (std::size_t i = 0; i < g.size(); ++i)
    if (g.position[i][2] <= 2.0) gone.push_back(g.id[i]);
  std::sort(gone.begin(), gone.end());
  std::int64_t bonds_left = 0;
  for (const auto& b : g.bonds)
    bonds_left += !std::binary_search(gone.begin(), gone.end(), b.a) &&
                  !std::binary_search(gone.begin(), gone.end(), b.b);
  ASSERT_GT(gone.size(), 10u);
  EXPECT_EQ(sim.remove_particles(d), static_cast<std::int64_t>(gone.size()));
  EXPECT_EQ(sim.total_particles(), static_cast<std::int64_t>(g.size() - gone.size()));
  EXPECT_EQ(sim.bond_count(), bonds_left);
  const auto s = state(sim);
  for (const auto id : gone) EXPECT_FALSE(s.count(id)) << id;
  basalt::test::random_velocities(sim, 1e-3);
  sim.run(200);  // (a bond to a removed particle would stop the run: "longer than the ghost width")
  EXPECT_EQ(static_cast<std::int64_t>(state(sim).size()), sim.total_particles());
  EXPECT_EQ(sim.bond_count(), bonds_left);
}

TEST(ParticleFlow, TheScenesEventsHappenAtTheirSteps) {
  // [[insert]] every 50 steps from step 0 to before 200 (4 events); [[delete]] of tag 0 below z = 0.9 every
  // 20 steps: the pile's bottom layer goes as step 20 begins, and the rest settles onto the floor.
  const auto scene = basalt::test::scene_from(pile_scene(R"(
[[insert]]
box = { min = [0.0, 0.0, 4.0], max = [4.0, 4.0, 7.0] }
radius = [0.3, 0.45]
count = 10
every = 50
stop = 200
tag = 3
[[delete]]
box = { min = [-1.0, -1.0, -1.0], max = [5.0, 5.0, 0.9] }
tags = [0]
every = 20
)"));
  Simulation<double> sim(scene, pile(), MPI_COMM_WORLD, basalt::test::quiet());
  EXPECT_EQ(sim.total_particles(), 48);
  sim.run(1);  // the insert at step 0 happens as the first step begins
  EXPECT_EQ(sim.flow_totals()[0], 10);
  EXPECT_EQ(sim.total_particles(), 58);
  sim.run(19);  // step 20 begins with the deletion: the next run's first step
  EXPECT_EQ(sim.flow_totals()[1], 0);
  sim.run(1);
  EXPECT_EQ(sim.flow_totals()[1], 16) << "the bottom layer (16 particles of tag 0)";
  sim.run(250);
  EXPECT_EQ(sim.flow_totals()[0], 40);
  const auto s = state(sim);
  EXPECT_EQ(static_cast<std::int64_t>(s.size()), 48 + 40 - sim.flow_totals()[1]);
  EXPECT_EQ(std::count_if(s.begin(), s.end(), [](const auto& e) { return e.second[4] == 3; }), 40);
}

TEST(ParticleFlow, RequestsThatDoNotFitTheRunAreRefused) {
  Simulation<double> sim(basalt::test::scene_from(pile_scene()), pile(), MPI_COMM_WORLD,
                         basalt::test::quiet());
  auto big = feed(5);
  big.rmin = big.rmax = 0.8;  // beyond the lists' reach (largest radius 0.5)
  EXPECT_THROW(sim.insert_particles(big), InputError);
  auto light = feed(5);
  light.rmin = 0.01;  // far lighter than the pile's grains: the run's dt is too long for their contacts
  try {
    sim.insert_particles(light);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lighter"), std::string::npos) << e.what();
  }
  EXPECT_EQ(sim.total_particles(), 48) << "a refused request inserts nothing";
  // Scene keys: a region a sphere cannot fit, a missing count.
  const auto bad = [](const std::string& body) {
    try {
      (void)basalt::test::scene_from(pile_scene(body));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(
      bad("[[insert]]\nbox = { min = [0.0, 0.0, 0.0], max = [0.5, 4.0, 4.0] }\nradius = 0.3\ncount = 1\n")
          .find("insert[0].radius"),
      std::string::npos);
  EXPECT_NE(
      bad("[[insert]]\nbox = { min = [0.0, 0.0, 0.0], max = [4.0, 4.0, 4.0] }\nradius = 0.3\n").find("count"),
      std::string::npos);
  EXPECT_NE(bad("[[delete]]\nevery = 10\n").find("box"), std::string::npos);
}
