// RebuildChecks (stability/rebuild_checks.hpp) on its own, on one rank: the float run's warning about
// positions so far from the origin that distances round to strains above kResolutionWarn (said once, and
// never at the start, where the load check spoke), and the double run's warning when the rounding of
// positions passes kStrainLossWarn of the largest bond strain seen so far (said once, never near the origin);
// a scene without a model that sees impacts makes no collision check. (Whole runs: test_lost_strain.cpp,
// test_contact_extremes.cpp.)
#include <gtest/gtest.h>
#include <mpi.h>

#include <string>
#include <vector>

#include "basalt/solver/core/bonds.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/interactions/force_field.hpp"
#include "basalt/solver/parallel/communicator.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/stability/rebuild_checks.hpp"

using namespace basalt::solver;

namespace {

/// Two particles of radius 0.5 at x = x0 and x0 + length along x, bonded with rest length 1 (local ends
/// resolved), in a scene with no interactions, on one rank.
template <class Real>
struct Pair {
  Scene scene;
  ForceField<Real> forces{scene};
  Comm comm{MPI_COMM_SELF};
  Particles<Real> p;
  Bonds<Real> bonds;
  Pair(double x0, double length) {
    p.push_owned(1, Real(x0), 0, 0, Real(0.5), 0, 1);
    p.push_owned(2, Real(x0 + length), 0, 0, Real(0.5), 0, 1);
    bonds.push(1, 2, 1, 0);
    bonds.ia = {0};
    bonds.ib = {1};
    bonds.n_both_owned = 1;
  }
  /// Moves the pair to x0, x0 + length.
  void place(double x0, double length) {
    p.x[0] = Real(x0);
    p.x[1] = Real(x0 + length);
  }
  typename RebuildChecks<Real>::State at(std::int64_t step) const {
    return {p, bonds, forces, comm, step, 0.5, sizeof(Real) == 4 ? "float" : "double"};
  }
};

/// Whether `text` holds `part`.
bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// What `check` printed to stderr.
template <class F>
std::string said(F check) {
  testing::internal::CaptureStderr();
  check();
  return testing::internal::GetCapturedStderr();
}

}  // namespace

// Float, smallest radius 0.5: the resolution is epsilon |x| = 1.19e-7 |x|, above kResolutionWarn = 1e-5 from
// |x| = 83.9 on.
TEST(RebuildChecks, FloatWarnsOnceWhenPositionsGoTooFar) {
  Pair<float> s(70, 1);
  RebuildChecks<float> checks;
  EXPECT_EQ(said([&] { checks.far_positions(s.at(10)); }), "");  // |x| = 71
  s.place(82, 1);
  EXPECT_EQ(said([&] { checks.far_positions(s.at(20)); }), "");  // |x| = 83: 9.9e-6, below
  s.place(89, 1);
  const auto w = said([&] { checks.far_positions(s.at(30)); });  // |x| = 90: 1.07e-5
  EXPECT_PRED2(has, w, "warning: step 30: particles have reached |x| = 90");
  EXPECT_PRED2(has, w, "in float");
  s.place(200, 1);
  EXPECT_EQ(said([&] { checks.far_positions(s.at(40)); }), "");  // said once
}

TEST(RebuildChecks, FloatLeavesTheStartToTheLoadCheck) {
  Pair<float> s(99, 1);
  RebuildChecks<float> checks;
  EXPECT_EQ(said([&] { checks.far_positions(s.at(0)); }), "");
  EXPECT_EQ(said([&] { checks.far_positions(s.at(10)); }), "");  // the load check has warned
}

// Double, smallest radius 0.5: the resolution is epsilon |x| = 2.2e-16 |x|; at |x| = 1e10, 2.2e-6, which
// is above 1e-3 of a strain of 1e-3 and below 1e-3 of a strain of 1e-2.
TEST(RebuildChecks, DoubleWarnsOnceWhenRoundingTakesTheStrains) {
  Pair<double> s(1e10, 1.001);
  RebuildChecks<double> checks;
  const auto w = said([&] { checks.lost_strain(s.at(50)); });
  EXPECT_PRED2(has, w, "warning: step 50: positions reach |x| = 1e+10");
  EXPECT_PRED2(has, w, "largest bond or contact strain of this run so far (0.001)");
  EXPECT_PRED2(has, w, "--precision mixed");
  EXPECT_EQ(said([&] { checks.lost_strain(s.at(60)); }), "");  // said once
}

TEST(RebuildChecks, DoubleComparesWithTheLargestStrainSoFar) {
  Pair<double> s(1e10, 1.01);  // strain 1e-2
  RebuildChecks<double> checks;
  EXPECT_EQ(said([&] { checks.lost_strain(s.at(10)); }), "");
  s.place(1e10, 1.001);  // strain 1e-3 now, but 1e-2 was seen
  EXPECT_EQ(said([&] { checks.lost_strain(s.at(20)); }), "");
  // Far enough for the largest strain too: 2.2e-16 * 1e11 = 2.2e-5 > 1e-3 * 1e-2.
  s.place(1e11, 1.01);
  EXPECT_PRED2(has, said([&] { checks.lost_strain(s.at(30)); }), "step 30");
}

TEST(RebuildChecks, DoubleIsQuietNearTheOrigin) {
  // At |x| = 5 the resolution is 1.1e-15: no strain a scene can resolve (>= 1e-9) is at risk, however
  // small the strains are.
  Pair<double> s(4, 1 + 1e-14);
  RebuildChecks<double> checks;
  EXPECT_EQ(said([&] { checks.lost_strain(s.at(10)); }), "");
}

TEST(RebuildChecks, NoCollisionCheckWithoutAModelThatSeesImpacts) {
  Pair<double> s(0, 1);
  RebuildChecks<double> checks;
  EXPECT_FALSE(checks.impacts(s.at(10), 1e-3, {}, false, 1e-3));
  EXPECT_EQ(checks.impact_report().checks, 0);
}
