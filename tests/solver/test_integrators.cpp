// The integrator kernels: the fused kick + kinetic energy gives exactly the bits of a kick followed
// by kinetic_energy(), and the kinetic energy a run saves (fused into the second half-kick) is the
// closed-form sum of m v^2 / 2 even after rebuilds reorder particles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <utility>

#include "basalt/solver/integrate/integrators.hpp"
#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;

namespace {

template <class Real>
Particles<Real> random_particles(std::size_t n, bool rotation = false, bool compensation = false) {
  Particles<Real> p;
  p.with_rotation = rotation;
  p.with_orientation = rotation;
  p.with_compensation = compensation;
  for (std::size_t i = 0; i < n; ++i) {
    const auto h = [&](std::uint64_t k) { return Real(basalt::test::hash_unit(7 * i + k)); };
    p.push_owned(std::int64_t(i), h(0), h(1), h(2), Real(0.3), 0, Real(1) / (Real(1.5) + h(3)), h(4), h(5),
                 h(6));
    p.fx[i] = 10 * h(7);
    p.fy[i] = 10 * h(8);
    p.fz[i] = 10 * h(9);
    if (rotation) {
      p.wx[i] = 40 * (h(10) - Real(0.5)), p.wy[i] = 40 * (h(11) - Real(0.5)),
      p.wz[i] = 40 * (h(12) - Real(0.5));
      p.tx[i] = h(13) - Real(0.5), p.ty[i] = h(14) - Real(0.5), p.tz[i] = h(15) - Real(0.5);
      p.qw[i] = Real(0.6), p.qx[i] = Real(0.48), p.qy[i] = Real(-0.64), p.qz[i] = 0;
    }
    if (compensation) p.cx[i] = Real(1e-9) * h(16), p.cy[i] = -Real(1e-9) * h(17), p.cz[i] = 0;
  }
  return p;
}

/// The pass that makes the last step's deferred second half-kick and this step's first one
/// (kick_kick_zero_drift, rotate_kick_kick_zero_drift) against the two passes it stands for: every array
/// the same bits, the largest displacement too. The two kicks differ (h0 != h), so swapped arguments fail.
template <class Real>
void expect_deferred_kick_is_exact(bool compensation) {
  const Real h0 = Real(0.004), h = Real(0.003), dt = Real(0.006);
  auto a = random_particles<Real>(1003, true, compensation);
  auto b = a;
  kick(a, h0);
  rotate_kick(a, h0);
  const double moved_a = kick_zero_drift(a, h, dt);
  rotate_kick_zero_drift(a, h, dt);
  const double moved_b = kick_kick_zero_drift(b, h0, h, dt);
  rotate_kick_kick_zero_drift(b, h0, h, dt);
  EXPECT_EQ(moved_a, moved_b);
  EXPECT_GT(moved_a, 0.0);
  for (auto v : {&Particles<Real>::x, &Particles<Real>::y, &Particles<Real>::z, &Particles<Real>::vx,
                 &Particles<Real>::vy, &Particles<Real>::vz, &Particles<Real>::fx, &Particles<Real>::fz,
                 &Particles<Real>::wx, &Particles<Real>::wy, &Particles<Real>::wz, &Particles<Real>::tx,
                 &Particles<Real>::tz, &Particles<Real>::qw, &Particles<Real>::qx, &Particles<Real>::qy,
                 &Particles<Real>::qz, &Particles<Real>::cx, &Particles<Real>::cz})
    EXPECT_EQ(a.*v, b.*v);
}

/// Without orientations (with_orientation false) the rotation pass is the kick alone: angular velocities
/// and torques get the bits of the pass that also turns orientations, with and without a pending kick.
template <class Real>
void expect_kick_without_orientation_is_exact() {
  const Real h0 = Real(0.004), h = Real(0.003), dt = Real(0.006);
  for (const bool pending : {false, true}) {
    auto a = random_particles<Real>(1003, true);
    auto b = a;
    b.with_orientation = false;
    for (auto q : {&Particles<Real>::qw, &Particles<Real>::qx, &Particles<Real>::qy, &Particles<Real>::qz})
      (b.*q).clear();
    if (pending) {
      rotate_kick_kick_zero_drift(a, h0, h, dt);
      rotate_kick_kick_zero_drift(b, h0, h, dt);
    } else {
      rotate_kick_zero_drift(a, h, dt);
      rotate_kick_zero_drift(b, h, dt);
    }
    EXPECT_NE(a.qw, random_particles<Real>(1003, true).qw);  // a's orientations turned
    EXPECT_TRUE(b.qw.empty());
    for (auto v : {&Particles<Real>::wx, &Particles<Real>::wy, &Particles<Real>::wz, &Particles<Real>::tx,
                   &Particles<Real>::ty, &Particles<Real>::tz})
      EXPECT_EQ(a.*v, b.*v) << pending;
  }
}

template <class Real>
void expect_fused_kick_is_exact() {
  auto a = random_particles<Real>(1003);  // not a multiple of the 8 lanes: blocks and a tail
  auto b = a;
  kick(a, Real(0.01));
  const double separate = kinetic_energy(a);
  const double fused = kick_energy(b, Real(0.01));
  EXPECT_EQ(fused, separate);
  EXPECT_EQ(a.vx, b.vx);
  EXPECT_EQ(a.vy, b.vy);
  EXPECT_EQ(a.vz, b.vz);
  double naive = 0;
  for (std::size_t i = 0; i < a.n_owned; ++i)
    naive += 0.5 / double(a.inv_mass[i]) *
             (double(a.vx[i]) * a.vx[i] + double(a.vy[i]) * a.vy[i] + double(a.vz[i]) * a.vz[i]);
  EXPECT_NEAR(fused, naive, 1e-13 * naive);
}

}  // namespace

TEST(Integrators, FusedKickEnergyEqualsKickThenKineticEnergyDouble) { expect_fused_kick_is_exact<double>(); }
TEST(Integrators, FusedKickEnergyEqualsKickThenKineticEnergyFloat) { expect_fused_kick_is_exact<float>(); }

TEST(Integrators, DeferredHalfKickInTheNextPassGivesTheSameBitsDouble) {
  expect_deferred_kick_is_exact<double>(false);
}
TEST(Integrators, DeferredHalfKickInTheNextPassGivesTheSameBitsFloat) {
  expect_deferred_kick_is_exact<float>(false);
}
TEST(Integrators, DeferredHalfKickInTheNextPassGivesTheSameBitsCompensated) {
  expect_deferred_kick_is_exact<float>(true);
}
TEST(Integrators, RotationWithoutOrientationGivesTheSameBitsDouble) {
  expect_kick_without_orientation_is_exact<double>();
}
TEST(Integrators, RotationWithoutOrientationGivesTheSameBitsFloat) {
  expect_kick_without_orientation_is_exact<float>();
}

TEST(Integrators, SavedKineticEnergyIsExactAcrossRebuilds) {
  const auto full = basalt::test::cube1();
  const auto g = basalt::test::sub_cube(full, 0.0, 4.0);
  ASSERT_GT(g.size(), 50u);
  // A thin skin and fast particles: the lists (and the particles' order in memory) are rebuilt often.
  const auto scene = basalt::test::scene_from(R"(
[run]
dt = 1e-3
steps = 300
skin = 0.002
energy_check_every = 0
[[interactions]]
type = "linear_elastic"
K = 1000.0
[output]
[[output.fields]]
type = "kinetic_energy"
)");
  Simulation<double> sim(scene, g, MPI_COMM_SELF);
  basalt::test::random_velocities(sim, 0.5);
  basalt::test::MemorySink sink;
  sink.begin({"kinetic_energy"});
  const auto& cp = std::as_const(sim).particles();
  int checked = 0;
  for (int k = 0; k < 300; ++k) {
    sim.step(&sink);
    if (sink.rows.empty() || !sink.rows.back()[0]) continue;
    // Closed form from the geometry's radii (density 1): independent of the solver's mass arrays.
    double expected = 0;
    for (std::size_t i = 0; i < cp.n_owned; ++i) {
      const double r = g.radius[static_cast<std::size_t>(g.index_of(cp.id[i]))];
      const double m = 4.0 / 3.0 * std::numbers::pi * r * r * r;
      expected += 0.5 * m * (cp.vx[i] * cp.vx[i] + cp.vy[i] * cp.vy[i] + cp.vz[i] * cp.vz[i]);
    }
    if (sink.steps.back() == sim.current_step()) {
      EXPECT_NEAR(*sink.rows.back()[0], expected, 1e-12 * expected) << "step " << sim.current_step();
      ++checked;
    }
  }
  EXPECT_GT(sim.rebuilds(), 5) << "the test needs rebuilds to mean anything";
  EXPECT_GT(checked, 100);
}

// The rotation's half-angle cos and sin / |w| (half_turn): a Taylor series below a half-angle of 0.1 rad,
// std::cos and std::sin above. Both branches must give the same values to rounding (within 2 ulp of the
// library's), over the angles a step really turns by and across the switch; w = 0 gives the identity.
TEST(Integrators, HalfTurnSeriesMatchesSinCosToRounding) {
  const double dt = 1e-3;
  for (double a = 1e-12; a < 0.4; a *= 1.07) {  // half-angle a = |w| dt / 2
    const double w = 2 * a / dt;
    double c = 0, s = 0;
    basalt::solver::half_turn(w * w, dt, c, s);
    const double want_c = std::cos(a), want_s = std::sin(a) / w;
    EXPECT_LE(std::abs(c - want_c), 2 * std::numeric_limits<double>::epsilon() * want_c) << "a = " << a;
    EXPECT_LE(std::abs(s - want_s), 2 * std::numeric_limits<double>::epsilon() * want_s) << "a = " << a;
  }
  double c = 0, s = 0;
  basalt::solver::half_turn(0.0, dt, c, s);
  EXPECT_EQ(c, 1.0);
  EXPECT_EQ(s, dt / 2);
}

// The pass runs branch-free in vector registers (a scalar tail for the last particles) and leaves the turns
// too large for the series to a second pass: each particle must get the same bits as when it is turned
// alone, whether it rests, turns a little or turns too far for the series, wherever it sits in the arrays
// (a rank's share and order of particles must not change them); and that is the turn by half_turn(),
// q <- dq q made unit, to rounding.
TEST(Integrators, RotationPassTurnsEachParticleAsAlone) {
  const double dt = 1e-3, h = 0.3e-3;
  Particles<double> p;
  p.with_rotation = true;
  p.with_orientation = true;
  for (std::size_t i = 0; i < 67; ++i) {
    p.push_owned(std::int64_t(i), 0, 0, double(i), 0.5 + 0.01 * double(i % 5), 0, 1.0 + 0.1 * double(i % 3));
    const auto u = [&](std::uint64_t k) { return basalt::test::hash_unit(17 * i + k) - 0.5; };
    // Every fifth at rest (with a torque of zero), every seventh spun past the series' range (a > 0.1).
    const double spin = i % 5 == 0 ? 0.0 : i % 7 == 0 ? 900.0 : 40.0;
    p.wx[i] = spin * u(0), p.wy[i] = spin * u(1), p.wz[i] = spin * u(2);
    p.tx[i] = i % 5 == 0 ? 0.0 : u(3), p.ty[i] = i % 5 == 0 ? 0.0 : u(4), p.tz[i] = i % 5 == 0 ? 0.0 : u(5);
    // Not quite unit orientations: a particle at rest must keep even these bits.
    p.qw[i] = 0.6 + 1e-9 * u(6), p.qx[i] = 0.48, p.qy[i] = -0.64 * u(7), p.qz[i] = 0.1;
  }
  const Particles<double> before = p;
  rotate_kick_zero_drift(p, h, dt);
  std::size_t large = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    Particles<double> one;
    one.with_rotation = true;
    one.with_orientation = true;
    one.push_owned(before.id[i], 0, 0, 0, before.radius[i], 0, before.inv_mass[i]);
    one.wx[0] = before.wx[i], one.wy[0] = before.wy[i], one.wz[0] = before.wz[i];
    one.tx[0] = before.tx[i], one.ty[0] = before.ty[i], one.tz[0] = before.tz[i];
    one.qw[0] = before.qw[i], one.qx[0] = before.qx[i], one.qy[0] = before.qy[i], one.qz[0] = before.qz[i];
    rotate_kick_zero_drift(one, h, dt);
    EXPECT_EQ(p.wx[i], one.wx[0]) << i;
    EXPECT_EQ(p.wy[i], one.wy[0]) << i;
    EXPECT_EQ(p.wz[i], one.wz[0]) << i;
    EXPECT_EQ(p.tx[i], 0.0) << i;
    EXPECT_EQ(p.qw[i], one.qw[0]) << i;
    EXPECT_EQ(p.qx[i], one.qx[0]) << i;
    EXPECT_EQ(p.qy[i], one.qy[0]) << i;
    EXPECT_EQ(p.qz[i], one.qz[0]) << i;
    // The turn itself, to rounding; at rest, the same bits.
    const double wx = p.wx[i], wy = p.wy[i], wz = p.wz[i], w2 = wx * wx + wy * wy + wz * wz;
    double qw = before.qw[i], qx = before.qx[i], qy = before.qy[i], qz = before.qz[i];
    if (w2 > 0) {
      large += w2 * (dt / 2) * (dt / 2) >= 1e-2;
      double c = 0, sn = 0;
      basalt::solver::half_turn(w2, dt, c, sn);
      basalt::solver::detail::turn(c, sn, wx, wy, wz, qw, qx, qy, qz);
    }
    const double tol = w2 > 0 ? 1e-15 : 0.0;
    EXPECT_NEAR(p.qw[i], qw, tol) << i;
    EXPECT_NEAR(p.qx[i], qx, tol) << i;
    EXPECT_NEAR(p.qy[i], qy, tol) << i;
    EXPECT_NEAR(p.qz[i], qz, tol) << i;
  }
  EXPECT_GT(large, 5u) << "the test needs turns past the series";
}

TEST(Integrators, OrientationsStayOfUnitLengthOverManySteps) {
  // Each turn keeps |q| to rounding, but over many steps the roundings add up unless q is brought back to
  // unit length every step (ESyS-Particle's CRotParticle::rescale). rot_bond's ESyS angles read a norm
  // defect e as a bend of sqrt(2 e), so a drift of 1e-14 is a 1.4e-7 rad kick on every bond
  // (docs/validation-rock.md, "Energy"). The former update (no renormalisation) reached |q|^2 - 1 = 1e-11
  // in 1e5 steps with spins like these.
  Particles<double> p;
  p.with_rotation = true;
  p.with_orientation = true;
  for (std::size_t i = 0; i < 64; ++i) {
    p.push_owned(std::int64_t(i), 0, 0, double(i), 0.5, 0, 1.0);
    const auto h = [&](std::uint64_t k) { return basalt::test::hash_unit(11 * i + k) - 0.5; };
    p.wx[i] = 3 * h(0);
    p.wy[i] = 3 * h(1);
    p.wz[i] = 3 * h(2);
  }
  double worst = 0;
  for (int step = 0; step < 100000; ++step) {
    rotate_kick_zero_drift(p, 0.0, 1e-3);
    if (step % 1000 == 999)
      for (std::size_t i = 0; i < p.n_owned; ++i)
        worst = std::max(worst, std::abs(p.qw[i] * p.qw[i] + p.qx[i] * p.qx[i] + p.qy[i] * p.qy[i] +
                                         p.qz[i] * p.qz[i] - 1));
  }
  std::printf("largest | |q|^2 - 1 | over 1e5 steps: %.3g\n", worst);
  EXPECT_LE(worst, 4 * std::numeric_limits<double>::epsilon());
}
