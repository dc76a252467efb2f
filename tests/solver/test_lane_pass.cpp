// The lane pass (interactions/lane_pass.hpp) that the pair and the wall drivers share, on a model whose every
// result names its entry: entry e's force is k e, evaluating it adds 1 to its history, it dissipates e and
// slides when e > 20, and its parting energy is what its history holds. Over entries that touch or not in
// patterns that end on a short batch, on a full batch followed by entries apart, and on no contact at all:
// - every contact's result is handed back once, in entry order (a short batch's copies dropped);
// - on real steps, the contacts' histories come back advanced and every entry apart is cleared (also after
//   the last batch), its history's parting energy tallied when counted; on other steps nothing changes;
// - the energy, dissipation and sliding count are the counted contacts' sums, and a tally handed to a second
//   pass runs on from the first (a wall driver's walls).
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <vector>

#include "basalt/solver/interactions/lane_pass.hpp"
#include "basalt/solver/models/lanes.hpp"

using namespace basalt::solver;

namespace {

/// A lane model whose results are its inputs' plain functions (exact in double).
struct Tracer {
  struct History {
    double seen = 0;  ///< what it held before (an entry's e + 1), plus one per real evaluation
  };
  template <class Real>
  struct Coeffs {
    Real k = 0;
  };
  template <bool Advance, class Real, int W>
  static void contact_lanes(const Coeffs<Real>& c, ContactLanes<Real, W, History>& L) {
    for (int l = 0; l < W; ++l) {
      L.fx[l] = c.k * L.dx[l];
      L.dissipated[l] = double(L.dx[l]);
      L.sliding[l] = L.dx[l] > Real(20) ? Real(1) : Real(0);
      if (Advance) L.h[l].seen += 1;
    }
  }
  static void apart(History& h) { h = History{}; }
  template <class Real>
  static double parting_energy(const Coeffs<Real>&, const History& h) {
    return h.seen;
  }
  template <class Real>
  static Real energy(const Coeffs<Real>& c, const History& h, const ContactKinematics<Real>& k) {
    return c.k * k.dx + Real(h.seen);
  }
};

using Lanes = ContactLanes<double, kContactLaneWidth, Tracer::History>;
using Pass = LanePass<double, Tracer, Lanes>;
constexpr double kK = 3;

/// A driver over entries [begin, end) of n: entry e touches when touch(e), is counted when e % 4 != 3.
struct Driver {
  std::vector<Tracer::History> hist;
  std::vector<double> force;
  std::vector<std::uint32_t> added;  ///< the entries whose results came back, in order
  LaneTally tally;
  std::function<bool(std::uint32_t)> touch;
  Lanes L{};

  Driver(std::uint32_t n, std::function<bool(std::uint32_t)> t)
      : hist(n), force(n, 0.0), touch(std::move(t)) {
    for (std::uint32_t e = 0; e < n; ++e) hist[e].seen = e + 1;
  }
  static bool counted(std::uint32_t e) { return e % 4 != 3; }

  template <bool Energy, bool Advance>
  void pass(std::uint32_t begin, std::uint32_t end) {
    alignas(64) std::uint32_t lane_e[kContactLaneWidth];
    const auto find = [&](std::uint32_t e, int l) {
      lane_e[l] = e;
      return LaneFound{touch(e), counted(e)};
    };
    const auto load = [&](int filled) {
      Pass::pad(lane_e, filled);
      for (int l = 0; l < kContactLaneWidth; ++l) L.dx[l] = double(lane_e[l]);
    };
    const auto add = [&](int l) {
      force[lane_e[l]] += L.fx[l];
      added.push_back(lane_e[l]);
      return counted(lane_e[l]);
    };
    const auto kinematics = [&](int l) {
      ContactKinematics<double> k{};
      k.dx = L.dx[l];
      return k;
    };
    Pass::run<Energy, Advance>(Tracer::Coeffs<double>{kK}, L, hist.data(), begin, end, tally, find, load, add,
                               kinematics);
  }
};

/// What a real step with energies must leave, entry by entry and in the tallies.
void expect_real_step(const Driver& r, std::uint32_t begin, std::uint32_t end, const char* what) {
  std::vector<std::uint32_t> contacts;
  LaneTally want;
  for (std::uint32_t e = 0; e < r.hist.size(); ++e) {
    const bool in = e >= begin && e < end;
    if (in && r.touch(e)) {
      contacts.push_back(e);
      EXPECT_EQ(r.force[e], kK * e) << what << ": entry " << e;
      EXPECT_EQ(r.hist[e].seen, e + 2.0) << what << ": a contact's history comes back advanced, entry " << e;
      if (Driver::counted(e)) {
        want.dissipated += e;
        want.sliding += e > 20;
        want.energy += kK * e + (e + 2.0);
      }
    } else {
      EXPECT_EQ(r.force[e], 0.0) << what << ": entry " << e;
      EXPECT_EQ(r.hist[e].seen, in ? 0.0 : e + 1.0)
          << what << ": an entry apart is cleared, one outside the pass untouched, entry " << e;
      if (in && Driver::counted(e)) want.parted += e + 1.0;
    }
  }
  EXPECT_EQ(r.added, contacts) << what << ": each contact once, in entry order";
  EXPECT_EQ(r.tally.energy, want.energy) << what;
  EXPECT_EQ(r.tally.dissipated, want.dissipated) << what;
  EXPECT_EQ(r.tally.parted, want.parted) << what;
  EXPECT_EQ(r.tally.sliding, want.sliding) << what;
}

}  // namespace

TEST(LanePass, EveryContactOnceInOrderHistoriesAdvancedOrClearedAndTallied) {
  // Two contacts in three: a full batch, then a short one (27 contacts of 40).
  Driver short_last(40, [](std::uint32_t e) { return e % 3 != 1; });
  short_last.pass<true, true>(0, 40);
  expect_real_step(short_last, 0, 40, "short last batch");
  // Two full batches, then eight entries apart: cleared after the last batch.
  Driver full_last(40, [](std::uint32_t e) { return e < 32; });
  full_last.pass<true, true>(0, 40);
  expect_real_step(full_last, 0, 40, "full last batch");
  // A range not starting at 0, with no contact at all.
  Driver none(20, [](std::uint32_t) { return false; });
  none.pass<true, true>(5, 17);
  expect_real_step(none, 5, 17, "no contact");
  // One contact, alone in its batch, among entries apart on either side.
  Driver one(30, [](std::uint32_t e) { return e == 22; });
  one.pass<true, true>(0, 30);
  expect_real_step(one, 0, 30, "one contact");
}

TEST(LanePass, OtherStepsChangeNoHistoryAndTallyNothingButTheEnergy) {
  Driver r(40, [](std::uint32_t e) { return e % 3 != 1; });
  r.pass<true, false>(0, 40);
  double energy = 0;
  for (std::uint32_t e = 0; e < 40; ++e) {
    EXPECT_EQ(r.hist[e].seen, e + 1.0) << "entry " << e;
    if (r.touch(e) && Driver::counted(e)) energy += kK * e + (e + 1.0);
  }
  EXPECT_EQ(r.tally.energy, energy);
  EXPECT_EQ(r.tally.dissipated, 0.0);
  EXPECT_EQ(r.tally.parted, 0.0);
  EXPECT_EQ(r.tally.sliding, 0u);
  // Without energies: none tallied.
  Driver quiet(40, [](std::uint32_t e) { return e % 3 != 1; });
  quiet.pass<false, false>(0, 40);
  EXPECT_EQ(quiet.tally.energy, 0.0);
  EXPECT_EQ(quiet.force, r.force);
}

TEST(LanePass, ATallyRunsOnFromPassToPass) {
  // One pass over [0, 40) against two over [0, 19) and [19, 40) with the same tally (a short batch each):
  // the same results, the same sums.
  const auto touch = [](std::uint32_t e) { return e % 3 != 1; };
  Driver whole(40, touch), halves(40, touch);
  whole.pass<true, true>(0, 40);
  halves.pass<true, true>(0, 19);
  halves.pass<true, true>(19, 40);
  expect_real_step(halves, 0, 40, "two passes");
  EXPECT_EQ(halves.tally.energy, whole.tally.energy);
  EXPECT_EQ(halves.tally.parted, whole.tally.parted);
}
