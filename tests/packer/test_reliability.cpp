// Issue 16, packer: inputs that crashed, ran out of memory or packed far too little (docs/reliability.md).
// Each test fails on the code before the fix: the steep exponents popped a radius off an empty list and
// overflowed r^-alpha; small volumes got 1 or 2 spheres because the void filler had no cell to start from.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include "basalt/packer/error.hpp"
#include "basalt/packer/pack.hpp"
#include "packing_checks.hpp"

using namespace basalt::packer;
namespace chk = basalt::packer::test;

namespace {

PackOptions options(double rmin, double rmax, std::uint64_t seed = 1) {
  return chk::options(rmin, rmax, seed);
}
using chk::expect_valid;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const PackError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

// ---- class 1: a crash, and memory without bound ---------------------------------------------------

TEST(Reliability, SteepPowerLawRadiiNeitherOverflowNorLoop) {
  // r^-alpha overflowed for alpha ln(1/rmin) > 709 (exponents 500-800 with rmin 0.2): no radius was
  // drawn; beyond that inf - inf gave NaN radii, appended without end.
  for (double alpha : {20.0, 600.0, 1e4, 1e308}) {
    const auto radii = power_law_radii(0.2, 0.5, alpha, 0.55 * 27, 1);
    for (double r : radii) {
      EXPECT_GE(r, 0.2) << alpha;
      EXPECT_LE(r, 0.5) << alpha;
    }
    EXPECT_LT(radii.size(), 10000u) << alpha;
  }
  // Up to the limit the law's volume is right, steep or flat (log1p keeps tiny exponents).
  for (double alpha : {1e-6, 0.5, 3.0, 20.0}) {
    const auto radii = power_law_radii(0.1, 1.0, alpha, 500.0, 2);
    double solid = 0;
    for (double r : radii) solid += 4.0 / 3.0 * M_PI * r * r * r;
    EXPECT_NEAR(solid, 500.0, 0.03 * 500) << alpha;
  }
}

TEST(Reliability, ExponentsBeyondTheUsefulRangeAreRefusedBeforePacking) {
  auto box = make_box({0, 0, 0}, {3, 3, 3});
  for (double alpha : {20.5, 500.0, 600.0, 800.0, 1e4, 1e308}) {
    auto o = options(0.2, 0.5);
    o.exponent = alpha;
    EXPECT_NE(error_of([&] { pack(*box, o); }).find("beyond the useful range (0, 20]"), std::string::npos)
        << alpha;
  }
  for (double alpha : {1e-3, 20.0}) {
    auto o = options(0.2, 0.5);
    o.exponent = alpha;
    expect_valid(*box, pack(*box, o), o);
  }
}

TEST(Reliability, PowerLawWithNoRadiusDrawnStillPacksOne) {
  // The target holds less than one sphere: no radius is drawn, the seeding places one of radius rmin,
  // and the code popped "the smallest drawn radius" off the empty list (undefined behaviour: a crash).
  auto box = make_box({0, 0, 0}, {1, 1, 1});
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    auto o = options(0.4, 0.5, seed);
    o.exponent = 2.0;
    o.target_fraction = 0.01;
    const auto p = pack(*box, o);
    expect_valid(*box, p, o);
    EXPECT_LE(p.size(), 2u);
  }
}

TEST(Reliability, ExpectedSphereCountIsNearTheRealOne) {
  auto box = make_box({0, 0, 0}, {6, 6, 6});
  const auto dense = options(0.2, 1.0);
  const double n = static_cast<double>(pack(*box, dense).size());
  const double e = expected_sphere_count(box->measure(), dense);
  EXPECT_GT(e, 0.5 * n);
  EXPECT_LT(e, 2.0 * n);
  auto pl = options(0.1, 1.0);
  pl.exponent = 2.2;
  const double drawn = static_cast<double>(power_law_radii(0.1, 1.0, 2.2, 0.55 * 216, 1).size());
  EXPECT_NEAR(expected_sphere_count(216, pl), drawn, 0.02 * drawn);
  // Absurd volumes give an absurd count, not a crash or a NaN.
  const double huge = expected_sphere_count(1e18, options(0.2, 0.5));
  EXPECT_GT(huge, 1e18);
  EXPECT_FALSE(std::isnan(expected_sphere_count(1e300, options(1e-300, 1.0))));
}

// ---- class 2: the dense packer in small volumes ---------------------------------------------------

TEST(Reliability, SmallBoxesAreFilledAtEverySeed) {
  // 2 x 2 x 2 with radii up to 0.5 got 2 spheres (0.13 solid), 2 to 24 depending on the seed.
  auto box = make_box({0, 0, 0}, {2, 2, 2});
  double lo = 1, hi = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const auto o = options(0.2, 0.5, seed);
    const auto p = pack(*box, o);
    expect_valid(*box, p, o);
    const double f = chk::solid_fraction(*box, p);
    lo = std::min(lo, f);
    hi = std::max(hi, f);
    EXPECT_GE(p.size(), 10u) << "seed " << seed;
  }
  EXPECT_GT(lo, 0.45);
  EXPECT_LT(hi - lo, 0.1);
}

TEST(Reliability, OneSeedSphereIsNotTheEnd) {
  // A unit box with rmin 0.1 got its one seed of radius 0.5 (eight corners hold 0.134 each), a ball of
  // radius 1.2 got 1, a 15 mm box with rmax 3.75 got 2.
  struct Case {
    std::unique_ptr<Volume> v;
    PackOptions o;
    double fraction;
    std::size_t count;
  };
  Case cases[] = {{make_box({0, 0, 0}, {1, 1, 1}), options(0.1, 0.5), 0.55, 7},
                  {make_sphere({0, 0, 0}, 1.2), options(0.2, 0.5), 0.45, 15},
                  {make_sphere({5, 5, 5}, 1.2), options(0.2, 0.5, 9), 0.45, 15},
                  {make_cylinder({0, 0, 0}, 1, 2), options(0.2, 0.5), 0.45, 15},
                  {make_box({0, 0, 0}, {15, 15, 15}), options(0.8, 3.75), 0.6, 30}};
  for (const auto& c : cases) {
    const auto p = pack(*c.v, c.o);
    expect_valid(*c.v, p, c.o);
    EXPECT_GT(chk::solid_fraction(*c.v, p), c.fraction) << c.v->description();
    EXPECT_GE(p.size(), c.count) << c.v->description();
  }
}

TEST(Reliability, PowerLawPlacesItsRadiiInSmallVolumes) {
  // A guard more than a regression: the power-law mode seeds with its many smaller radii and placed these
  // before too; it checks the probes that now look for room for a radius no void holds.
  auto box = make_box({0, 0, 0}, {2, 2, 2});
  auto o = options(0.2, 0.5, 3);
  o.exponent = 2.0;
  o.target_fraction = 0.4;
  const auto p = pack(*box, o);
  expect_valid(*box, p, o);
  EXPECT_GT(chk::solid_fraction(*box, p), 0.3);
  EXPECT_LE(p.not_placed * 4, p.requested);
}

TEST(Reliability, LowFractionsAreExplained) {
  // Normal packs say nothing.
  auto cube = make_box({0, 0, 0}, {8, 8, 8});
  const auto normal = options(0.2, 1.0);
  const auto p = pack(*cube, normal);
  EXPECT_TRUE(low_fraction_report(*cube, normal, p, chk::solid_fraction(*cube, p)).text.empty());
  // One sphere of radius 0.5 in a 1.2 box: nothing else fits; far below, with the reasons.
  auto small = make_box({0, 0, 0}, {1.2, 1.2, 1.2});
  const auto equal = options(0.5, 0.5);
  const auto q = pack(*small, equal);
  ASSERT_EQ(q.size(), 1u);
  const auto rep = low_fraction_report(*small, equal, q, chk::solid_fraction(*small, q));
  EXPECT_TRUE(rep.far_below);
  for (const char* w : {"far below the dense mode's 0.70", "no room is left",
                        "1.2 spheres of radius rmax across", "rmax / rmin = 1"})
    EXPECT_NE(rep.text.find(w), std::string::npos) << w << " missing from: " << rep.text;
  // A moderately low fraction (a 2 x 2 x 2 box is all wall layer) is a note, not an error.
  auto box = make_box({0, 0, 0}, {2, 2, 2});
  const auto o = options(0.2, 0.5);
  const auto r = pack(*box, o);
  const auto note = low_fraction_report(*box, o, r, chk::solid_fraction(*box, r));
  EXPECT_FALSE(note.far_below);
  EXPECT_NE(note.text.find("2 spheres of radius rmax across"), std::string::npos) << note.text;
  // Power-law radii left unplaced are counted.
  Packing unplaced = r;
  unplaced.requested = 40;
  unplaced.not_placed = 30;
  auto pl = o;
  pl.exponent = 2.0;
  pl.target_fraction = 0.6;
  const auto prep = low_fraction_report(*box, pl, unplaced, 0.2);
  EXPECT_TRUE(prep.far_below);
  EXPECT_NE(prep.text.find("30 of the 40 radii drawn found no room"), std::string::npos) << prep.text;
}
