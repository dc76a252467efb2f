// RebuildSchedule (neighbor/rebuild_schedule.hpp) and FixedParticles (core/fixed_particles.hpp) on their own:
// when the lists are rebuilt (a move beyond half the skin, a non-finite move, a bond broken unknown to the
// lists, another reason), what a rebuild clears and counts, the far moves taken once; which particles are
// held and what holding them zeroes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "basalt/solver/core/fixed_particles.hpp"
#include "basalt/solver/neighbor/rebuild_schedule.hpp"

using namespace basalt::solver;

TEST(RebuildSchedule, AMoveBeyondHalfTheSkinRebuilds) {
  RebuildSchedule s;
  s.configure(0.2);  // limit (0.1)^2
  const double limit2 = 0.25 * 0.2 * 0.2;
  EXPECT_FALSE(s.exceeded(s.need(0.0, false)));
  EXPECT_FALSE(s.exceeded(s.need(limit2, false)));  // at the limit: not yet
  EXPECT_TRUE(s.exceeded(s.need(std::nextafter(limit2, 1.0), false)));
  EXPECT_EQ(s.need(0.003, false), 0.003);  // the move itself, for the ranks' largest
  EXPECT_TRUE(s.exceeded(std::numeric_limits<double>::quiet_NaN()));  // a position went non-finite
  EXPECT_TRUE(s.exceeded(std::numeric_limits<double>::infinity()));
  EXPECT_TRUE(s.exceeded(s.need(0.0, true)));  // another reason (balancer, particles in or out)
  EXPECT_FALSE(s.pending());
}

TEST(RebuildSchedule, ABrokenBondRebuildsUntilTheNextRebuild) {
  RebuildSchedule s;
  s.configure(0.2);
  s.bond_parted();
  EXPECT_TRUE(s.pending());
  EXPECT_TRUE(s.exceeded(s.need(0.0, false)));
  EXPECT_TRUE(s.exceeded(s.need(0.0, false)));  // asking does not clear it
  s.rebuilt(7);
  EXPECT_FALSE(s.pending());
  EXPECT_FALSE(s.exceeded(s.need(0.0, false)));
  s.set_pending(true);  // a restart's rebuild_pending
  EXPECT_TRUE(s.exceeded(s.need(0.0, false)));
  s.set_pending(false);  // put back after a trial that broke bonds
  EXPECT_FALSE(s.exceeded(s.need(0.0, false)));
}

TEST(RebuildSchedule, RebuildsAreCountedAndDated) {
  RebuildSchedule s;
  s.configure(0.1);
  EXPECT_EQ(s.count(), 0);
  EXPECT_EQ(s.last_step(), 0);
  s.rebuilt(0);
  s.rebuilt(12);
  EXPECT_EQ(s.count(), 2);
  EXPECT_EQ(s.last_step(), 12);
  s.set_last_step(13);  // a rebuild inside step 13 used that step's positions
  EXPECT_EQ(s.last_step(), 13);
  EXPECT_EQ(s.count(), 2);
}

TEST(RebuildSchedule, FarMovesAreAllowedForOneMigration) {
  RebuildSchedule s;
  EXPECT_FALSE(s.take_far_moves());
  s.allow_far_moves();
  s.rebuilt(3);  // (a rebuild's bookkeeping does not take them: the migration does)
  EXPECT_TRUE(s.take_far_moves());
  EXPECT_FALSE(s.take_far_moves());
}

TEST(FixedParticles, HoldsTheParticlesOfTheTagsOnly) {
  Particles<double> p;
  p.with_rotation = true;
  const std::vector<std::int32_t> tags{0, 3, 1, 3, 2, 0, 3};
  for (std::size_t i = 0; i < tags.size(); ++i) {
    p.push_owned(std::int64_t(i), double(i), 0, 0, 0.5, tags[i], 1.0, 1.0 + double(i), 2, 3);
    p.fx[i] = p.fy[i] = p.fz[i] = 4;
    p.tx[i] = p.ty[i] = p.tz[i] = 5;
    p.wx[i] = p.wy[i] = p.wz[i] = 6;
  }
  FixedParticles f;
  f.find(p, {});
  EXPECT_TRUE(f.indices().empty());
  f.find(p, {3, 2});
  EXPECT_EQ(f.indices(), (std::vector<std::uint32_t>{1, 3, 4, 6}));
  f.find(p, {});  // no fixed tags any more: none held
  EXPECT_TRUE(f.indices().empty());
  f.find(p, {3, 2});
  f.hold(p);
  f.stop(p);
  for (std::size_t i = 0; i < tags.size(); ++i) {
    const bool held = tags[i] == 3 || tags[i] == 2;
    SCOPED_TRACE(i);
    EXPECT_EQ(p.fx[i], held ? 0.0 : 4.0);
    EXPECT_EQ(p.fy[i], held ? 0.0 : 4.0);
    EXPECT_EQ(p.fz[i], held ? 0.0 : 4.0);
    EXPECT_EQ(p.tx[i], held ? 0.0 : 5.0);
    EXPECT_EQ(p.ty[i], held ? 0.0 : 5.0);
    EXPECT_EQ(p.tz[i], held ? 0.0 : 5.0);
    EXPECT_EQ(p.vx[i], held ? 0.0 : 1.0 + double(i));
    EXPECT_EQ(p.vy[i], held ? 0.0 : 2.0);
    EXPECT_EQ(p.vz[i], held ? 0.0 : 3.0);
    EXPECT_EQ(p.wx[i], held ? 0.0 : 6.0);
    EXPECT_EQ(p.wy[i], held ? 0.0 : 6.0);
    EXPECT_EQ(p.wz[i], held ? 0.0 : 6.0);
  }
  f.find(p, {1});  // new tags replace the old
  EXPECT_EQ(f.indices(), (std::vector<std::uint32_t>{2}));
}
