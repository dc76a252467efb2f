// VelocityVerlet (integrate/verlet.hpp) on its own: the integrator's state between steps and its rules.
//   pending   a second half-kick left for the next first_half() (second_half with defer) gives the bits of
//             one made at once, and settle() makes it exactly once;
//   zeroed    first_half() zeroes the forces and says so once (take_zeroed), as mark_zeroed() does;
//   energy    kinetic_energy() has a value only after an undeferred second half-kick that computed it, until
//             the next first_half() or forget_energy();
//   kicks     velocity Verlet: dt/2 before the drift and dt/2 after; symplectic Euler: dt before, none after.
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>

#include "basalt/solver/integrate/integrators.hpp"
#include "basalt/solver/integrate/verlet.hpp"
#include "geometries.hpp"

using namespace basalt::solver;

namespace {

/// n rotating particles with random positions, velocities, spins and forces.
template <class Real>
Particles<Real> moving_particles(std::size_t n, bool rotation) {
  Particles<Real> p;
  p.with_rotation = rotation;
  p.with_orientation = rotation;
  for (std::size_t i = 0; i < n; ++i) {
    const auto h = [&](std::uint64_t k) {
      return Real(0.5 * basalt::test::hash_unit(11 * i + k));
    };  // [-0.5, 0.5)
    p.push_owned(std::int64_t(i), h(0), h(1), h(2), Real(0.3), 0, Real(1) / (Real(1.5) + h(3)), h(4), h(5),
                 h(6));
    p.fx[i] = 10 * h(7), p.fy[i] = 10 * h(8), p.fz[i] = 10 * h(9);
    if (rotation) {
      p.wx[i] = 40 * h(10), p.wy[i] = 40 * h(11), p.wz[i] = 40 * h(12);
      p.tx[i] = h(13), p.ty[i] = h(14), p.tz[i] = h(15);
    }
  }
  return p;
}

/// A force and torque that depend on the positions and spins (so that a kick made at the wrong time, or
/// missed, changes the next forces): a spring to the origin and a drag on the spin.
template <class Real>
void spring_forces(Particles<Real>& p) {
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    p.fx[i] += -3 * p.x[i], p.fy[i] += -3 * p.y[i], p.fz[i] += -3 * p.z[i];
    if (p.with_rotation) p.tx[i] += -p.wx[i] / 8, p.ty[i] += -p.wy[i] / 8, p.tz[i] += -p.wz[i] / 8;
  }
}

template <class Real>
void expect_same_state(const Particles<Real>& a, const Particles<Real>& b) {
  for (auto v : {&Particles<Real>::x, &Particles<Real>::y, &Particles<Real>::z, &Particles<Real>::vx,
                 &Particles<Real>::vy, &Particles<Real>::vz, &Particles<Real>::fx, &Particles<Real>::fy,
                 &Particles<Real>::fz, &Particles<Real>::wx, &Particles<Real>::wy, &Particles<Real>::wz,
                 &Particles<Real>::qw, &Particles<Real>::qx, &Particles<Real>::qy, &Particles<Real>::qz})
    EXPECT_EQ(a.*v, b.*v);
}

/// Ten steps with every second half-kick made at once (a) and deferred into the next first pass (b), then
/// b's last one settled: the same bits, and the same largest move at every step.
template <class Real>
void expect_deferred_kicks_give_the_same_bits(bool rotation) {
  auto a = moving_particles<Real>(203, rotation);
  auto b = a;
  VelocityVerlet<Real> va, vb;
  va.configure(1e-2, false);
  vb.configure(1e-2, false);
  for (int step = 0; step < 10; ++step) {
    EXPECT_EQ(va.first_half(a), vb.first_half(b)) << "step " << step;
    spring_forces(a);
    spring_forces(b);
    va.second_half(a, false, false);
    vb.second_half(b, true, false);
  }
  EXPECT_NE(a.vx, b.vx);  // b's last kick still pending
  vb.settle(b);
  expect_same_state(a, b);
  vb.settle(b);  // nothing pending any more: no second kick
  expect_same_state(a, b);
  va.settle(a);  // nothing was pending
  expect_same_state(a, b);
}

}  // namespace

TEST(VelocityVerlet, DeferredKicksGiveTheBitsOfKicksMadeAtOnceDouble) {
  expect_deferred_kicks_give_the_same_bits<double>(false);
}
TEST(VelocityVerlet, DeferredKicksGiveTheBitsOfKicksMadeAtOnceRotating) {
  expect_deferred_kicks_give_the_same_bits<double>(true);
}
TEST(VelocityVerlet, DeferredKicksGiveTheBitsOfKicksMadeAtOnceFloat) {
  expect_deferred_kicks_give_the_same_bits<float>(true);
}

// The first pass is the kernels' kick by dt/2, zeroed forces and drift by dt (velocity Verlet), or the whole
// kick by dt (symplectic Euler); the second pass kicks by dt/2, or does nothing (and defers nothing).
TEST(VelocityVerlet, KicksSplitTheStepAsTheSchemeSays) {
  const double dt = 1e-2;
  for (const bool euler : {false, true}) {
    SCOPED_TRACE(euler ? "symplectic Euler" : "velocity Verlet");
    auto p = moving_particles<double>(101, true);
    auto q = p;
    VelocityVerlet<double> v;
    v.configure(dt, euler);
    const double moved = v.first_half(p);
    const double h1 = euler ? dt : dt / 2;
    EXPECT_EQ(moved, kick_zero_drift(q, h1, dt));
    rotate_kick_zero_drift(q, h1, dt);
    expect_same_state(p, q);
    spring_forces(p);
    spring_forces(q);
    v.second_half(p, false, false);
    if (!euler) {
      kick(q, dt / 2);
      rotate_kick(q, dt / 2);
    }
    expect_same_state(p, q);
    v.second_half(p, true, false);  // deferred: nothing now, and (Euler) nothing later either
    expect_same_state(p, q);
    v.settle(p);
    if (!euler) {
      kick(q, dt / 2);
      rotate_kick(q, dt / 2);
    }
    expect_same_state(p, q);
  }
}

// first_half() zeroes the forces and torques, and take_zeroed() says so once; mark_zeroed() (a caller that
// zeroed them) the same. The force computation adds onto zeroed forces only when told.
TEST(VelocityVerlet, ForcesZeroedAreReportedOnce) {
  auto p = moving_particles<double>(37, true);
  VelocityVerlet<double> v;
  v.configure(1e-3, false);
  EXPECT_FALSE(v.take_zeroed());
  v.first_half(p);
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    ASSERT_EQ(p.fx[i], 0.0);
    ASSERT_EQ(p.fz[i], 0.0);
    ASSERT_EQ(p.tx[i], 0.0);
    ASSERT_EQ(p.tz[i], 0.0);
  }
  EXPECT_TRUE(v.take_zeroed());
  EXPECT_FALSE(v.take_zeroed());
  v.second_half(p, false, true);
  EXPECT_FALSE(v.take_zeroed());  // a kick does not zero them
  v.mark_zeroed();
  EXPECT_TRUE(v.take_zeroed());
  EXPECT_FALSE(v.take_zeroed());
}

// The kinetic energy the second half-kick computes: the exact sum of kinetic_energy() after it, and only
// until something may change the velocities (the next first pass, forget_energy()); none from a deferred
// kick or one not asked for it.
TEST(VelocityVerlet, KineticEnergyIsKnownOnlyAfterAnUndeferredKickThatComputedIt) {
  auto p = moving_particles<double>(57, false);
  VelocityVerlet<double> v;
  v.configure(1e-2, false);
  EXPECT_FALSE(v.kinetic_energy());
  v.first_half(p);
  spring_forces(p);
  v.second_half(p, false, true);
  ASSERT_TRUE(v.kinetic_energy());
  EXPECT_EQ(*v.kinetic_energy(), kinetic_energy(p));
  EXPECT_GT(*v.kinetic_energy(), 0.0);
  v.forget_energy();
  EXPECT_FALSE(v.kinetic_energy());

  v.first_half(p);
  spring_forces(p);
  v.second_half(p, false, true);
  EXPECT_TRUE(v.kinetic_energy());
  v.first_half(p);  // the velocities move on
  EXPECT_FALSE(v.kinetic_energy());
  spring_forces(p);
  v.second_half(p, true, true);  // deferred: computes none
  EXPECT_FALSE(v.kinetic_energy());
  v.first_half(p);
  spring_forces(p);
  v.second_half(p, false, false);  // not asked for
  EXPECT_FALSE(v.kinetic_energy());
}
