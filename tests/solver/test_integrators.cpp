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
#include "solver_helpers.hpp"
#include "test_support.hpp"

using namespace basalt::solver;

namespace {

template <class Real>
Particles<Real> random_particles(std::size_t n) {
  Particles<Real> p;
  for (std::size_t i = 0; i < n; ++i) {
    const auto h = [&](std::uint64_t k) { return Real(basalt::test::hash_unit(7 * i + k)); };
    p.push_owned(std::int64_t(i), h(0), h(1), h(2), Real(0.3), 0, Real(1) / (Real(1.5) + h(3)), h(4), h(5),
                 h(6));
    p.fx[i] = 10 * h(7);
    p.fy[i] = 10 * h(8);
    p.fz[i] = 10 * h(9);
  }
  return p;
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

TEST(Integrators, SavedKineticEnergyIsExactAcrossRebuilds) {
  const auto full = basalt::io::read_geometry(basalt::test::reference_dir() / "cube1.geo");
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
  auto& p = sim.particles();
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const auto id = static_cast<std::uint64_t>(p.id[i]);
    p.vx[i] = 0.5 * basalt::test::hash_unit(3 * id);
    p.vy[i] = 0.5 * basalt::test::hash_unit(3 * id + 1);
    p.vz[i] = 0.5 * basalt::test::hash_unit(3 * id + 2);
  }
  sim.state_changed();
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

TEST(Integrators, OrientationsStayOfUnitLengthOverManySteps) {
  // Each turn keeps |q| to rounding, but over many steps the roundings add up unless q is brought back to
  // unit length every step (ESyS-Particle's CRotParticle::rescale). rot_bond's ESyS angles read a norm
  // defect e as a bend of sqrt(2 e), so a drift of 1e-14 is a 1.4e-7 rad kick on every bond
  // (docs/validation-rock.md, "Energy"). The former update (no renormalisation) reached |q|^2 - 1 = 1e-11
  // in 1e5 steps with spins like these.
  Particles<double> p;
  p.with_rotation = true;
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
