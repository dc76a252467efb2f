// ParticleFlow (core/particle_flow.hpp) on its own, on one rank: the scene's [[insert]] and [[delete]] events
// queued at their steps and held until the next rebuild's exchange; the exchange removing the deletions'
// particles with their bonds and appending the arrivals with ids from the counter; changed() set only when
// particles came or went, until settled(). (Whole runs with insertion and deletion: test_particle_flow.cpp.)
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <set>
#include <vector>

#include "basalt/solver/core/bonds.hpp"
#include "basalt/solver/core/particle_flow.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/parallel/communicator.hpp"
#include "basalt/solver/parallel/decomposition.hpp"
#include "basalt/solver/scene/scene.hpp"

using namespace basalt::solver;

namespace {

InsertSpec insert_every(std::int64_t start, std::int64_t every, std::int64_t stop) {
  InsertSpec s;
  s.name = "feed";
  s.region.lo = {1.0, 1.0, 7.0};
  s.region.hi = {9.0, 9.0, 9.0};
  s.rmin = s.rmax = 0.3;
  s.density = 1;
  s.count = 3;
  s.start = start;
  s.every = every;
  s.stop = stop;
  return s;
}

DeleteSpec delete_in(std::array<double, 3> lo, std::array<double, 3> hi, std::int64_t every = 1) {
  DeleteSpec d;
  d.name = "outlet";
  d.region.lo = lo;
  d.region.hi = hi;
  d.every = every;
  return d;
}

/// Four particles in a row along x at 1, 3, 5, 7 (ids 1-4, tags 0, 7, 0, 7) in the box [0, 10]^3, bonded
/// 1-2, 2-3, 3-4, on one rank.
struct Row {
  Comm comm{MPI_COMM_SELF};
  Decomposition dec{comm, {1, 1, 1}, {0.0, 0.0, 0.0}, {10.0, 10.0, 10.0}};
  Particles<double> p;
  Bonds<double> bonds;
  Row() {
    for (int k = 0; k < 4; ++k) p.push_owned(k + 1, 1.0 + 2 * k, 5.0, 5.0, 0.4, k % 2 == 1 ? 7 : 0, 1.0);
    for (std::int64_t a = 1; a < 4; ++a) bonds.push(a, a + 1, 2.0, 0);
  }
  std::vector<std::int64_t> ids() const {
    std::vector<std::int64_t> v(p.id.begin(), p.id.begin() + std::ptrdiff_t(p.n_owned));
    std::sort(v.begin(), v.end());
    return v;
  }
  std::vector<std::array<std::int64_t, 2>> bond_ends() const {
    std::vector<std::array<std::int64_t, 2>> v;
    for (std::size_t k = 0; k < bonds.size(); ++k) v.push_back({bonds.a[k], bonds.b[k]});
    return v;
  }
};

}  // namespace

TEST(ParticleFlowQueue, QueuesTheScenesEventsAtTheirSteps) {
  Scene scene;
  scene.inserts = {insert_every(10, 5, 25)};                       // steps 10, 15, 20
  scene.deletes = {delete_in({0, 0, 0}, {1, 1, 1}, /*every=*/4)};  // steps 4, 8, 12, ... (never 0)
  const std::set<std::int64_t> due{4, 8, 10, 12, 15, 16, 20, 24, 28};
  for (std::int64_t s = 0; s <= 30; ++s) {
    ParticleFlow<double> f;
    EXPECT_EQ(f.queue(scene, s), due.count(s) == 1) << "step " << s;
    EXPECT_EQ(f.pending(), due.count(s) == 1) << "step " << s;
    EXPECT_FALSE(f.changed()) << "queueing alone changes nothing, step " << s;
  }
}

TEST(ParticleFlowQueue, InsertsOnlyFromStartUntilStop) {
  Scene scene;
  scene.inserts = {insert_every(0, 3, 9)};  // steps 0, 3, 6 (9 is the stop)
  for (std::int64_t s = 0; s <= 12; ++s) {
    ParticleFlow<double> f;
    EXPECT_EQ(f.queue(scene, s), s == 0 || s == 3 || s == 6) << "step " << s;
  }
}

TEST(ParticleFlowQueue, EventsWaitForTheNextExchange) {
  Row row;
  Scene scene;
  scene.deletes = {delete_in({0, 0, 0}, {2, 10, 10}, 5)};
  ParticleFlow<double> f;
  EXPECT_TRUE(f.queue(scene, 5));
  EXPECT_TRUE(f.queue(scene, 6));  // still queued: no rebuild since
  f.exchange(row.p, row.bonds, row.dec);
  EXPECT_FALSE(f.pending());
  EXPECT_FALSE(f.queue(scene, 6));
  EXPECT_EQ(row.ids(), (std::vector<std::int64_t>{2, 3, 4}));
}

TEST(ParticleFlowQueue, DeletionTakesTheRegionsParticlesAndTheirBonds) {
  Row row;
  ParticleFlow<double> f;
  f.queue(delete_in({4, 0, 0}, {6, 10, 10}));  // particle 3 at x = 5
  EXPECT_TRUE(f.pending());
  EXPECT_FALSE(f.changed());
  f.exchange(row.p, row.bonds, row.dec);
  EXPECT_EQ(row.ids(), (std::vector<std::int64_t>{1, 2, 4}));
  EXPECT_EQ(row.bond_ends(), (std::vector<std::array<std::int64_t, 2>>{{1, 2}}));
  EXPECT_EQ(f.last(), (std::array<std::int64_t, 2>{0, 1}));
  EXPECT_EQ(f.totals(), (std::array<std::int64_t, 2>{0, 1}));
  EXPECT_TRUE(f.changed());
  EXPECT_FALSE(f.pending());
  f.settled();
  EXPECT_FALSE(f.changed());
  // The same region again: nobody left there, nothing changes.
  f.queue(delete_in({4, 0, 0}, {6, 10, 10}));
  f.exchange(row.p, row.bonds, row.dec);
  EXPECT_EQ(f.last(), (std::array<std::int64_t, 2>{0, 0}));
  EXPECT_EQ(f.totals(), (std::array<std::int64_t, 2>{0, 1}));
  EXPECT_FALSE(f.changed());
  EXPECT_EQ(row.ids(), (std::vector<std::int64_t>{1, 2, 4}));
}

TEST(ParticleFlowQueue, DeletionKeepsOtherTags) {
  Row row;
  ParticleFlow<double> f;
  auto d = delete_in({0, 0, 0}, {10, 10, 10});
  d.tags = {7};  // particles 2 and 4
  f.queue(d);
  f.exchange(row.p, row.bonds, row.dec);
  EXPECT_EQ(row.ids(), (std::vector<std::int64_t>{1, 3}));
  EXPECT_TRUE(row.bond_ends().empty());  // every bond had an end of tag 7
  EXPECT_EQ(f.last(), (std::array<std::int64_t, 2>{0, 2}));
}

TEST(ParticleFlowQueue, ArrivalsTakeIdsAfterTheGeometrysLast) {
  Row row;
  Scene scene;
  scene.inserts = {insert_every(0, 1, 100)};
  GeometryExtent e;
  e.lo = {0.6, 4.6, 4.6};
  e.hi = {7.4, 5.4, 5.4};
  e.rmax = 0.4;
  e.n = 4, e.first_id = 1, e.last_id = 4;
  ParticleFlow<double> f;
  f.include(scene, e);
  EXPECT_EQ(f.next_id(), 5);
  EXPECT_EQ(f.rmax(), 0.4);
  EXPECT_EQ(e.hi[2], 9.0);  // the lists' box covers the insert's region
  EXPECT_FALSE(f.ids_issued());
  ASSERT_TRUE(f.queue(scene, 0));
  f.plan_arrivals(row.p, row.dec, 0);
  f.exchange(row.p, row.bonds, row.dec);
  EXPECT_EQ(row.ids(), (std::vector<std::int64_t>{1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(f.next_id(), 8);
  EXPECT_TRUE(f.ids_issued());
  EXPECT_EQ(f.last(), (std::array<std::int64_t, 2>{3, 0}));
  EXPECT_TRUE(f.changed());
  for (std::size_t i = 4; i < row.p.n_owned; ++i) {
    EXPECT_EQ(row.p.radius[i], 0.3);
    EXPECT_GE(row.p.z[i], 7.3);
  }
  // The next event's arrivals continue the count.
  f.settled();
  ASSERT_TRUE(f.queue(scene, 1));
  f.plan_arrivals(row.p, row.dec, 1);
  f.exchange(row.p, row.bonds, row.dec);
  EXPECT_EQ(row.ids().back(), 10);
  EXPECT_EQ(f.totals(), (std::array<std::int64_t, 2>{6, 0}));
  EXPECT_TRUE(f.changed());
}
