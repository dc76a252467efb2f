// EnergyGuard (stability/energy_guard.hpp) on its own: which steps need the energies (the guard's, the
// potential and kinetic savers'), the walls' work put in, the balance E + dissipated - work in - E0 held up
// to the allowed growth and broken just above it, and the reference after a start or a rebase.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "basalt/solver/core/ledger.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/stability/energy_guard.hpp"

using namespace basalt::solver;

namespace {

/// kinetic_energy, bond_energy (potential), gravity_energy (potential, a body force's), wall_work_in (work),
/// friction_dissipated (dissipated): the values of v are in this order.
Ledger ledger() {
  Ledger l;
  l.add("kinetic_energy", Ledger::Kind::kinetic);
  l.add("bond_energy", Ledger::Kind::potential);
  l.add("gravity_energy", Ledger::Kind::potential);
  l.add("wall_work_in", Ledger::Kind::work);
  l.add("friction_dissipated", Ledger::Kind::dissipated);
  return l;
}

constexpr std::size_t kGravity = 2;
const auto no_body = [](std::size_t) { return false; };

/// A saver of `type` (of ledger term `term` for an energy) every `every` steps.
FieldSpec saver(FieldSpec::Type type, std::int64_t every, const char* term = "") {
  FieldSpec f;
  f.type = type;
  f.every = every;
  if (type == FieldSpec::Type::energy) f.term = term;
  return f;
}

/// The guard every `every` steps (0: off), with these savers.
EnergyGuard guard(std::int64_t every, std::vector<FieldSpec> savers = {}) {
  Scene scene;
  scene.energy_check_every = every;
  scene.fields = std::move(savers);
  return EnergyGuard(scene, ledger());
}

}  // namespace

TEST(EnergyGuard, ChecksAtMultiplesOfItsEveryOnly) {
  const auto g = guard(100);
  for (const std::int64_t s : {0, 100, 200, 1000}) EXPECT_TRUE(g.due(s)) << s;
  for (const std::int64_t s : {1, 99, 101, 150, 199}) EXPECT_FALSE(g.due(s)) << s;
  // The guard's steps need both energies.
  EXPECT_TRUE(g.energy_due(300));
  EXPECT_TRUE(g.kinetic_due(300));
  EXPECT_FALSE(g.energy_due(301));
  EXPECT_FALSE(g.kinetic_due(301));
}

TEST(EnergyGuard, OffNeverChecks) {
  const auto g = guard(0);
  for (const std::int64_t s : {0, 1, 100}) {
    EXPECT_FALSE(g.due(s)) << s;
    EXPECT_FALSE(g.energy_due(s)) << s;
    EXPECT_FALSE(g.kinetic_due(s)) << s;
  }
}

TEST(EnergyGuard, SaversSayWhichEnergiesAStepNeeds) {
  // A potential's saver every 7, the kinetic energy's every 5, the total's every 11, a work term's every 3
  // (work accumulates: no energy is computed for it); the guard is off.
  const auto g =
      guard(0, {saver(FieldSpec::Type::energy, 7, "bond_energy"),
                saver(FieldSpec::Type::energy, 5, "kinetic_energy"), saver(FieldSpec::Type::total_energy, 11),
                saver(FieldSpec::Type::energy, 3, "wall_work_in")});
  EXPECT_TRUE(g.energy_due(7));
  EXPECT_TRUE(g.energy_due(14));
  EXPECT_FALSE(g.kinetic_due(7));
  EXPECT_TRUE(g.kinetic_due(5));
  EXPECT_FALSE(g.energy_due(5));
  EXPECT_TRUE(g.energy_due(22));
  EXPECT_TRUE(g.kinetic_due(22));
  for (const std::int64_t s : {3, 6, 8, 9, 13}) {
    EXPECT_FALSE(g.energy_due(s)) << s;
    EXPECT_FALSE(g.kinetic_due(s)) << s;
  }
  for (const std::int64_t s : {5, 7, 11}) EXPECT_FALSE(g.due(s)) << s;
}

TEST(EnergyGuard, CountsOnlyTheWorkPutIn) {
  auto g = guard(100);
  EXPECT_EQ(g.wall_work_in(), 0.0);
  g.add_wall_work(2.0, 0.5);   // +1
  g.add_wall_work(-8.0, 0.5);  // the walls took energy out: not work put in
  g.add_wall_work(6.0, 0.25);  // +1.5
  EXPECT_EQ(g.wall_work_in(), 2.5);
  g.clear_wall_work();
  EXPECT_EQ(g.wall_work_in(), 0.0);
  g.add_wall_work(1.0, 0.5);
  EXPECT_EQ(g.wall_work_in(), 0.5);
}

TEST(EnergyGuard, HoldsUpToTheAllowedGrowthAndBreaksAboveIt) {
  const auto l = ledger();
  auto g = guard(100);
  g.start(l, {1.0, 1.0, 0.0, 0.0, 0.0});  // E0 = 2
  // No work, no dissipation: allowed |E0| = 2, so E up to 2 E0 = 4 holds.
  EXPECT_FALSE(g.breach(l, {2.0, 1.0, 0.0, 0.0, 0.0}, no_body));
  EXPECT_FALSE(g.breach(l, {3.0, 1.0, 0.0, 0.0, 0.0}, no_body));  // exactly at the threshold
  const auto b = g.breach(l, {3.5, 1.0, 0.0, 0.0, 0.0}, no_body);
  ASSERT_TRUE(b);
  EXPECT_EQ(b->mechanical, 4.5);
  EXPECT_EQ(b->energy0, 2.0);
  EXPECT_EQ(b->imbalance, 2.5);
  EXPECT_EQ(b->allowed, 2.0);
  EXPECT_EQ(b->work, 0.0);
  EXPECT_EQ(b->dissipated, 0.0);
  // A mechanical energy that is not finite breaks it.
  EXPECT_TRUE(g.breach(l, {std::numeric_limits<double>::infinity(), 1.0, 0.0, 0.0, 0.0}, no_body));
  EXPECT_TRUE(g.breach(l, {std::numeric_limits<double>::quiet_NaN(), 1.0, 0.0, 0.0, 0.0}, no_body));
}

TEST(EnergyGuard, WorkInAndDissipationMoveTheBalance) {
  const auto l = ledger();
  auto g = guard(100);
  g.start(l, {1.0, 1.0, 0.0, 0.0, 0.0});  // E0 = 2
  // Work in W = 1, dissipated D = 0.5: imbalance E + D - W - E0, allowed |E0| + W + D = 3.5, so E <= 6.
  EXPECT_FALSE(g.breach(l, {5.0, 1.0, 0.0, 1.0, 0.5}, no_body));  // imbalance 3.5: at the threshold
  const auto b = g.breach(l, {5.5, 1.0, 0.0, 1.0, 0.5}, no_body);
  ASSERT_TRUE(b);
  EXPECT_EQ(b->imbalance, 4.0);
  EXPECT_EQ(b->allowed, 3.5);
  EXPECT_EQ(b->work, 1.0);
  EXPECT_EQ(b->dissipated, 0.5);
  // Energy that went into dissipation is no growth: E fell to 0.5 while 1.5 was dissipated.
  EXPECT_FALSE(g.breach(l, {0.5, 0.0, 0.0, 0.0, 1.5}, no_body));
}

TEST(EnergyGuard, ABodyForcesReleasedPotentialIsAllowed) {
  const auto l = ledger();
  auto g = guard(100);
  g.start(l, {0.0, 1.0, 1.0, 0.0, 0.0});  // E0 = 2, gravity's potential at 1
  // Gravity's potential fell from 1 to -3 (released 4, counted from the reference's 1) and the kinetic
  // energy grew to 10: imbalance 6, allowed 2 + 4 = 6 when gravity counts as a body force, 2 when not.
  const std::vector<double> v{10.0, 1.0, -3.0, 0.0, 0.0};
  EXPECT_FALSE(g.breach(l, v, [](std::size_t t) { return t == kGravity; }));
  EXPECT_TRUE(g.breach(l, v, no_body));
  // Released beyond the allowed: kinetic 12.5, imbalance 8.5 > 6.
  EXPECT_TRUE(g.breach(l, {12.5, 1.0, -3.0, 0.0, 0.0}, [](std::size_t t) { return t == kGravity; }));
}

TEST(EnergyGuard, RebaseCountsTheWorkAndDissipationSoFar) {
  const auto l = ledger();
  auto g = guard(100);
  // After particles came or went: K 1, P 1, W 2, D 0.5 -> E0 = 2 + 0.5 - 2 = 0.5, the balance is 0 here.
  const std::vector<double> at{1.0, 1.0, 0.0, 2.0, 0.5};
  g.rebase(l, at);
  EXPECT_FALSE(g.breach(l, at, no_body));
  const auto b = g.breach(l, {9.0, 1.0, 0.0, 2.0, 0.5}, no_body);
  ASSERT_TRUE(b);
  EXPECT_EQ(b->energy0, 0.5);
  EXPECT_EQ(b->imbalance, 8.0);            // 10 + 0.5 - 2 - 0.5
  EXPECT_EQ(b->allowed, 0.5 + 2.0 + 0.5);  // |E0| + W + D
  // start() takes the mechanical energy alone (a run's first reference): E0 = 2.
  g.start(l, at);
  const auto c = g.breach(l, {9.0, 1.0, 0.0, 2.0, 0.5}, no_body);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->energy0, 2.0);
  // The reference's body potentials are the rebased ones: gravity at 5 now, released 5 - 1 = 4 counts.
  g.rebase(l, {1.0, 1.0, 5.0, 2.0, 0.5});  // E0 = 7 + 0.5 - 2 = 5.5
  EXPECT_FALSE(g.breach(l, {14.0, 1.0, 1.0, 2.0, 0.5}, [](std::size_t t) { return t == kGravity; }));
  EXPECT_TRUE(g.breach(l, {14.0, 1.0, 1.0, 2.0, 0.5}, no_body));
}
