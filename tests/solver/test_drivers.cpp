// What the interaction drivers share (interactions/driver_base.hpp, history_records.hpp), and the drift
// between their copies it removed:
// - a contact history restored at a rebuild for a pair that is now bonded is dropped with its parting
//   energy dissipated for every model that names a dissipation term: the scalar JKR law too (the copy in
//   the pair driver tallied it for velocity-dependent models only, so a JKR neck whose pair got bonded
//   took its energy out of the ledger unaccounted);
// - contact records go out and come back through the helpers unchanged, flipped when found the other way
//   round, the cleared histories (+0 bits only) left out;
// - a bond's break record gives the same point from either end, in double whatever the precision of the
//   run (the rotational bond driver summed the radii and took the difference in Real);
// - the pair driver counts the contacts sliding at a real step over both parts of the step (owned pairs,
//   then pairs to a ghost), afresh each real step, and keeps the count through a step that is not real
//   (one rule for every contact driver: ContactDriver::start_step), pair by pair and in lanes alike;
// - a scalar law's pair loop tallies the parting energy of a history lost when its pair stops interacting
//   (a JKR neck that breaks), as the velocity-dependent loops do (the copy in the scalar loop ignored it).
#include <gtest/gtest.h>

#include <any>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "basalt/solver/interactions/driver_base.hpp"
#include "basalt/solver/interactions/history_records.hpp"
#include "basalt/solver/interactions/pair_driver.hpp"
#include "basalt/solver/models/friction.hpp"
#include "basalt/solver/models/hertz_mindlin.hpp"
#include "basalt/solver/models/jkr.hpp"
#include "scene_runs.hpp"

using namespace basalt::solver;

namespace {

/// Two overlapping spheres (ids 0 and 1), their pair listed once, marked bonded or not.
struct TwoSpheres {
  Particles<double> p;
  PairList own, ghost;
  explicit TwoSpheres(bool bonded) {
    p.push_owned(0, 0.0, 0.0, 0.0, 1.0, 0, 1.0);
    p.push_owned(1, 1.9, 0.0, 0.0, 1.0, 0, 1.0);
    own.offset = {0, 1, 1};
    own.neigh = {1};
    if (bonded) own.bonded = {1};
    own.index_loose();
    ghost.offset = {0, 0, 0};
  }
};

InteractionSpec jkr_group() {
  InteractionSpec g;
  g.name = "contact";
  g.model = "jkr";
  g.params = Jkr::Params{1e6, 0.25, 10.0};
  return g;
}

}  // namespace

TEST(Drivers, HistoryOfAPairNowBondedPartsWithItsEnergyForAScalarLaw) {
  for (const bool bonded : {true, false}) {
    TwoSpheres s(bonded);
    PairDriver<double, Jkr> driver({jkr_group()});
    ASSERT_EQ(driver.dissipation_term(), "adhesion_dissipated");
    Jkr::History h{};
    h.a = 0.1;
    h.energy = 2.5;
    driver.pending()->push(1, 0, reinterpret_cast<const double*>(&h));  // saved the other way round
    driver.rebuild(PairLists<double>{s.p, s.own, s.ghost, 1, {}}, 0);
    ContactRecords kept;
    driver.history_records(s.p, kept);
    if (bonded) {
      // The bond acts instead: the neck's energy is dissipated, its history cleared.
      EXPECT_EQ(driver.dissipated(), 2.5);
      EXPECT_EQ(kept.size(), 0U);
    } else {
      EXPECT_EQ(driver.dissipated(), 0.0);
      ASSERT_EQ(kept.size(), 1U);
      EXPECT_EQ(kept.a[0], 0);
      EXPECT_EQ(kept.b[0], 1);
      EXPECT_EQ(kept.at(0)[1], 2.5);
    }
  }
}

namespace {
/// A history with an orientation: seen from the other particle its vector turns round.
struct Oriented {
  struct History {
    double t[3];
  };
  static History flip(const History& h) { return {{-h.t[0], -h.t[1], -h.t[2]}}; }
};
}  // namespace

TEST(Drivers, RecordsGoOutAndComeBackThroughTheHelpers) {
  TwoSpheres s(false);
  s.p.push_owned(7, 5.0, 0.0, 0.0, 1.0, 0, 1.0);
  s.own.offset = {0, 2, 2, 2};
  s.own.neigh = {1, 2};
  std::vector<Oriented::History> hist{{{1.0, -2.0, 3.0}}, {{-0.0, 0.0, 0.0}}};
  EXPECT_TRUE(holds(hist[0]));
  EXPECT_TRUE(holds(hist[1]));  // a -0 is a bit set
  hist[1] = {};
  EXPECT_FALSE(holds(hist[1]));
  ContactRecords out;
  collect_pairs<Oriented>(s.p, s.own, hist, out);
  ASSERT_EQ(out.size(), 1U);  // the cleared history is left out
  EXPECT_EQ(out.width, 3U);
  // Listed the other way round (1, 0): found, and flipped.
  PairList back;
  back.offset = {0, 0, 1, 1};
  back.neigh = {0};
  std::vector<Oriented::History> again;
  const ContactLookup records(out);
  restore_pairs<Oriented>(s.p, back, out, records, again);
  ASSERT_EQ(again.size(), 1U);
  EXPECT_EQ(again[0].t[0], -1.0);
  EXPECT_EQ(again[0].t[1], 2.0);
  EXPECT_EQ(again[0].t[2], -3.0);
  // A wall's candidates: by (particle id, -1 - wall index).
  const std::vector<std::int32_t> cand{2, 0};
  std::vector<Oriented::History> wh{{{0.5, 0.0, 0.0}}, {}};
  ContactRecords wout;
  wout.width = 3;
  collect_candidates(s.p, cand, wh, wall_record_id(3), wout);
  ASSERT_EQ(wout.size(), 1U);
  EXPECT_EQ(wout.a[0], 7);
  EXPECT_EQ(wout.b[0], -4);
  std::vector<Oriented::History> wagain;
  const ContactLookup wrecords(wout);
  restore_candidates(s.p, std::vector<std::int32_t>{0, 2}, wout, wrecords, wall_record_id(3), wagain);
  ASSERT_EQ(wagain.size(), 2U);
  EXPECT_FALSE(holds(wagain[0]));
  EXPECT_EQ(wagain[1].t[0], 0.5);
}

template <class Real>
void expect_break_point_from_either_end() {
  const std::array<Real, 3> x1{Real(1234.5678), Real(-0.125), Real(3.3)},
      x2{Real(1235.9), Real(0.7), Real(3.1)};
  const Real r1 = Real(0.61), r2 = Real(0.83);
  const auto a = broken_bond<Real>(4, 9, 1.0, 1.0, 0, 0, x1, r1, x2, r2);
  const auto b = broken_bond<Real>(4, 9, 1.0, 1.0, 0, 0, x2, r2, x1, r1);
  // In double from the Real inputs: the two ends agree to double rounding, whatever Real is.
  EXPECT_NEAR(a.x, b.x, 1e-12);
  EXPECT_NEAR(a.y, b.y, 1e-12);
  EXPECT_NEAR(a.z, b.z, 1e-12);
  const double w = double(r1) / (double(r1) + double(r2));
  EXPECT_EQ(a.x, double(x1[0]) + w * (double(x2[0]) - double(x1[0])));
  EXPECT_EQ(a.step, -1);
}

TEST(Drivers, BreakRecordIsTheSamePointFromEitherEnd) {
  expect_break_point_from_either_end<double>();
  expect_break_point_from_either_end<float>();
}

namespace {
/// Sphere 0 touching sphere 1 (owned) and sphere 2 (a ghost) on either side along x, both sliding past it
/// along y; each pair listed once, from sphere 0.
struct SlidingPair {
  Particles<double> p;
  PairList own, ghost;
  Bonds<double> bonds;
  std::vector<BrokenBond> broken;
  Walls walls{std::vector<WallSpec>{}};
  SlidingPair() {
    p.push_owned(0, 0.0, 0.0, 0.0, 1.0, 0, 1.0);
    p.push_owned(1, 1.9, 0.0, 0.0, 1.0, 0, 1.0, 0.0, 1.0);
    p.push_owned(2, -1.9, 0.0, 0.0, 1.0, 0, 1.0, 0.0, 1.0);
    p.n_owned = 2;  // sphere 2 is a ghost
    own.offset = {0, 1, 1};
    own.neigh = {1};
    own.index_loose();
    ghost.offset = {0, 1, 1};
    ghost.neigh = {2};
    ghost.index_loose();
  }
  /// One step of the driver: the owned part, then the ghost part.
  void step(ForceCompute<double>& d, bool advance) {
    ForceState<double> s{p, bonds, broken, walls};
    d.compute(s, Part::owned, false, advance);
    d.compute(s, Part::ghost, false, advance);
  }
};

template <class Model>
void expect_both_parts_counted(const std::string& law) {
  SlidingPair s;
  const auto scene =
      basalt::test::scene_from("[run]\ndt = 0.01\nsteps = 0\nskin = 0.1\n[[interactions]]\n" + law);
  PairDriver<double, Model> driver(scene.contacts);
  driver.set_time_step(0.01);
  driver.rebuild(PairLists<double>{s.p, s.own, s.ghost, 1, {}}, 0);
  for (int step = 0; step < 3; ++step) {
    s.step(driver, true);
    EXPECT_EQ(driver.sliding_contacts(), 2U)
        << law << "step " << step << ": the owned pair and the pair to a ghost";
  }
  s.step(driver, false);
  EXPECT_EQ(driver.sliding_contacts(), 2U) << law << "a step that is not real counts nothing";
}
}  // namespace

TEST(Drivers, SlidingContactsCountBothPartsOfARealStepOnce) {
  // Pair by pair (a scalar contact()), and in lanes (contact_lanes).
  expect_both_parts_counted<Friction>("type = \"friction\"\nK = 1.0\nKs = 1.0\nmu = 0.01\n");
  expect_both_parts_counted<HertzMindlin>("type = \"hertz_mindlin\"\nE = 1.0e4\nnu = 0.25\nmu = 0.01\n");
}

TEST(Drivers, ScalarLoopTalliesTheEnergyOfANeckThatBreaks) {
  TwoSpheres s(false);
  PairDriver<double, Jkr> driver({jkr_group()});
  driver.rebuild(PairLists<double>{s.p, s.own, s.ghost, 1, {}}, 0);
  Bonds<double> bonds;
  std::vector<BrokenBond> broken;
  Walls walls{std::vector<WallSpec>{}};
  ForceState<double> st{s.p, bonds, broken, walls};
  driver.compute(st, Part::owned, false, true);  // the spheres overlap: a neck forms
  ContactRecords neck;
  driver.history_records(s.p, neck);
  ASSERT_EQ(neck.size(), 1U);
  const double held = neck.at(0)[1];
  ASSERT_GT(held, 0.0);
  EXPECT_EQ(driver.dissipated(), 0.0);
  s.p.x[1] = 5.0;  // far beyond the neck's reach, still listed
  driver.compute(st, Part::owned, false, false);
  EXPECT_EQ(driver.dissipated(), 0.0) << "a step that is not real changes no history";
  driver.compute(st, Part::owned, false, true);
  EXPECT_EQ(driver.dissipated(), held) << "the neck broke: what it held is dissipated";
  ContactRecords none;
  driver.history_records(s.p, none);
  EXPECT_EQ(none.size(), 0U) << "and its history cleared";
}
