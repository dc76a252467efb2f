// Clock (core/clock.hpp) on its own: the step and its time after each tick, step x dt to the bit with no
// change of dt, the time going on from the current step after a new dt, a scene's clock base, a restart's
// step and time.
#include <gtest/gtest.h>

#include <cstdint>

#include "basalt/solver/core/clock.hpp"

using basalt::solver::Clock;

TEST(Clock, TicksAtStepTimesDt) {
  Clock c;
  c.set_dt(0.1);
  EXPECT_EQ(c.step(), 0);
  EXPECT_EQ(c.time(), 0.0);
  for (std::int64_t s = 1; s <= 1000; ++s) {
    c.tick();
    ASSERT_EQ(c.step(), s);
    ASSERT_EQ(c.time(), double(s) * 0.1) << "step " << s;  // to the bit: no sum of increments
  }
  EXPECT_EQ(c.time_at(2000), 2000 * 0.1);
  EXPECT_EQ(c.dt(), 0.1);
}

TEST(Clock, ANewDtCountsOnFromNow) {
  Clock c;
  c.set_dt(0.5);
  for (int k = 0; k < 10; ++k) c.tick();  // step 10 at 5
  c.rebase();
  c.set_dt(0.25);
  EXPECT_EQ(c.time(), 5.0);
  EXPECT_EQ(c.time_at(10), 5.0);
  EXPECT_EQ(c.time_at(14), 6.0);
  c.tick();
  EXPECT_EQ(c.step(), 11);
  EXPECT_EQ(c.time(), 5.25);
  // Without the rebase the time would jump back to step x dt.
  Clock d;
  d.set_dt(0.5);
  for (int k = 0; k < 10; ++k) d.tick();
  d.set_dt(0.25);
  d.tick();
  EXPECT_EQ(d.time(), 2.75);
}

TEST(Clock, BaseAndRestart) {
  Clock c;
  c.set_dt(0.25);
  c.set_base(100, 10.0);  // a staged run whose dt changed at step 100, time 10
  EXPECT_EQ(c.time_at(104), 11.0);
  c.set(104, 11.0);  // the checkpoint's step and time
  c.tick();
  EXPECT_EQ(c.step(), 105);
  EXPECT_EQ(c.time(), 11.25);
  c.set_step(90);  // the step alone (a replayed rebuild), the time kept
  EXPECT_EQ(c.step(), 90);
  EXPECT_EQ(c.time(), 11.25);
  EXPECT_EQ(c.time_at(90), 7.5);
}
