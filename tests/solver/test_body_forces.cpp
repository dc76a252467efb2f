// Body forces and the energy ledger: gravity against the closed form of free fall (velocity Verlet is
// exact for a constant force), the ledger's balance (kinetic + gravity's potential conserved), a pile
// starting at rest under gravity that the energy guard lets run, and an unstable run under gravity
// that it still stops; ESyS's iterated damping evaluated on all particles at once against its scalar form.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/models/damping.hpp"
#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;

namespace {

using basalt::test::mass_of;

double term(const Simulation<double>& sim, const std::vector<double>& v, const std::string& name) {
  const int t = sim.ledger().find(name);
  EXPECT_GE(t, 0) << name;
  return t < 0 ? 0 : v[static_cast<std::size_t>(t)];
}

}  // namespace

TEST(Gravity, FreeFallFollowsTheClosedFormAndConservesTheLedger) {
  // g = -9.81e-3 mm/ms^2 along z, two spheres far apart (no contact), one tagged 1 that gravity skips.
  const auto scene = basalt::test::scene_from(R"(
[run]
dt = 0.1
steps = 0
skin = 0.1
energy_check_every = 1
[[body_forces]]
type = "gravity"
acceleration = [0.0, 0.0, -9.81e-3]
tags = [0]
[[output.fields]]
type = "gravity_potential_energy"
)");
  basalt::io::Geometry g;
  g.add_particle(1, {0, 0, 10}, 0.5, 0);
  g.add_particle(2, {5, 0, 10}, 0.5, 1);
  Simulation<double> sim(scene, g, MPI_COMM_SELF);
  const double m = mass_of(0.5), gz = -9.81e-3;
  const auto v0 = sim.ledger_values();
  EXPECT_NEAR(term(sim, v0, "gravity_potential_energy"), -m * gz * 10, 1e-15);
  sim.run(500);
  const auto& p = sim.particles();
  const double t = 500 * 0.1;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const double want = p.id[i] == 1 ? 10 + 0.5 * gz * t * t : 10;  // tag 1 is not pulled
    EXPECT_NEAR(p.z[i], want, 1e-9 * std::abs(want)) << "id " << p.id[i];
    EXPECT_NEAR(p.vz[i], p.id[i] == 1 ? gz * t : 0.0, 1e-12) << "id " << p.id[i];
  }
  const auto v = sim.ledger_values();
  const double e0 = term(sim, v0, "kinetic_energy") + term(sim, v0, "gravity_potential_energy");
  const double e = term(sim, v, "kinetic_energy") + term(sim, v, "gravity_potential_energy");
  EXPECT_GT(term(sim, v, "kinetic_energy"), 0.5 * m * 0.24);  // it really fell: v = 0.49 mm/ms
  EXPECT_NEAR(e, e0, 1e-12 * std::abs(e0));
}

// Untagged gravity takes one vector loop over all particles (Gravity::apply_all) on the steps that do not
// tally its potential, and the per-particle form on those that do: the same bits. Two falls, one tallying
// the energy at every step and one never, must keep every particle at the same place and speed; masses
// of many radii make any other rounding of m g show.
TEST(Gravity, VectorLoopGivesTheBitsOfThePerParticleForm) {
  const auto scene = [](int every) {
    return basalt::test::scene_from(R"(
[run]
dt = 0.1
steps = 0
skin = 0.1
energy_check_every = )" + std::to_string(every) +
                                    R"(
[[body_forces]]
type = "gravity"
acceleration = [1.0e-4, -2.0e-3, -9.81e-3]
)");
  };
  basalt::io::Geometry g;
  for (int k = 0; k < 37; ++k)  // apart (no contacts); not a multiple of a vector's width
    g.add_particle(k + 1, {3.0 * k, 0, 10}, 0.3 + 0.1 * basalt::test::hash_unit(std::uint64_t(k)), 0);
  Simulation<double> tallied(scene(1), g, MPI_COMM_SELF), plain(scene(0), g, MPI_COMM_SELF);
  tallied.run(300);
  plain.run(300);
  const auto& a = tallied.particles();
  const auto& b = plain.particles();
  ASSERT_EQ(a.n_owned, 37u);
  for (std::size_t i = 0; i < a.n_owned; ++i) {
    ASSERT_EQ(a.id[i], b.id[i]);
    EXPECT_EQ(a.vx[i], b.vx[i]) << "id " << a.id[i];
    EXPECT_EQ(a.vy[i], b.vy[i]) << "id " << a.id[i];
    EXPECT_EQ(a.vz[i], b.vz[i]) << "id " << a.id[i];
    EXPECT_EQ(a.z[i], b.z[i]) << "id " << a.id[i];
    EXPECT_NEAR(a.vz[i], -9.81e-3 * 30, 1e-12);  // it fell
  }
}

TEST(Gravity, PileAtRestUnderGravityRunsAndTheGuardStillStopsABlowUp) {
  // A column of spheres on an elastic floor, starting at rest under gravity: they fall and settle. The
  // column is centred on z = 0, so the mechanical energy starts near zero and the guard's margin is
  // the potential energy gravity released; the guard (every 10 steps) must not mistake the kinetic
  // energy the fall produces for energy from nowhere.
  const std::string body = R"(
[run]
dt = 0.002
steps = 0
skin = 0.05
energy_check_every = 10
[[interactions]]
type = "linear_elastic"
K = 1000.0
[[walls]]
name = "floor"
point = [0.0, 0.0, -3.0]
normal = [0.0, 0.0, 1.0]
K = 1000.0
[[body_forces]]
type = "gravity"
acceleration = [0.0, 0.0, -1.0]
)";
  basalt::io::Geometry g;
  for (int k = 0; k < 5; ++k) g.add_particle(k + 1, {0.01 * k, 0, -2.4 + 1.2 * k}, 0.5);
  Simulation<double> sim(basalt::test::scene_from(body), g, MPI_COMM_SELF);
  EXPECT_NO_THROW(sim.run(3000));
  const auto v = sim.ledger_values();
  // The spheres close gaps of 0.1 (floor) and 4 x 0.2: their heights drop by 2.5 in total.
  EXPECT_LT(term(sim, v, "gravity_potential_energy"), -0.8 * mass_of(0.5) * 1.0 * 2.5)
      << "the column must have come down";

  // The same column with dt above the critical step (forced): energy appears from nowhere; stopped.
  std::string fast = body;
  fast.replace(fast.find("dt = 0.002"), 10, "dt = 0.06");
  RunOptions forced;
  forced.force_dt = true;
  Simulation<double> unstable(basalt::test::scene_from(fast), g, MPI_COMM_SELF, forced);
  try {
    unstable.run(3000);
    ADD_FAILURE() << "an unstable run under gravity went on";
  } catch (const RunError& e) {
    // The blow-up check (a particle moving more than half the smallest radius in a step) comes first
    // since it exists; the energy guard remains behind it.
    const std::string msg = e.what();
    EXPECT_TRUE(msg.find("blow-up: particle id") != std::string::npos ||
                msg.find("gravity_potential_energy") != std::string::npos)
        << msg;
  }
  EXPECT_LT(unstable.current_step(), 3000);
}

TEST(Gravity, SaverOfATermNoModelFillsIsRefused) {
  const auto scene = basalt::test::scene_from(R"(
[run]
dt = 0.1
steps = 0
skin = 0.1
[[output.fields]]
type = "gravity_potential_energy"
)");
  basalt::io::Geometry g;
  g.add_particle(1, {0, 0, 0}, 0.5);
  try {
    Simulation<double> sim(scene, g, MPI_COMM_SELF);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("output.fields[0]"), std::string::npos) << e.what();
  }
}

template <class Real>
void all_at_once_matches_the_scalar_form() {
  // BodyDriver evaluates linear_damping and rotational_damping on every particle in one vector loop
  // (apply_all) that stops after two of ESyS's iterations and leaves the particles still iterating to the
  // scalar form. ESyS's form iterates per particle until its update is small or the limit is reached
  // (then no damping): each particle must get exactly what apply() gives it. Speeds from 1e-6 to 10 put
  // particles on both sides of the first test (|u| > 1e-3 iterates again); nu dt up to 0.9 makes the
  // iteration slow to converge (particles beyond two iterations); limits of 0 (the explicit form), 1, 2,
  // 5 and 50 iterations.
  constexpr std::size_t N = 37;  // (not a multiple of a vector's width)
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(-1, 1), exponent(-6, 1);
  const auto value = [&] { return Real(unit(rng) * std::pow(10.0, exponent(rng))); };
  int zeroed = 0, damped = 0, beyond_two = 0;
  for (const double nu_dt : {2e-7, 0.3, 0.9})
    for (const int limit : {0, 1, 2, 5, 50})
      for (int batch = 0; batch < 10; ++batch) {
        const Real dt = Real(1e-3), nu = Real(nu_dt / 1e-3);
        std::vector<Real> im(N), rad(N), vx(N), vy(N), vz(N), fx(N), fy(N), fz(N), wx(N), wy(N), wz(N), tx(N),
            ty(N), tz(N);
        std::vector<double> lin_out(N), rot_out(N);
        std::vector<std::uint8_t> flag(N);
        std::array<BodyState<Real>, N> b{};
        for (std::size_t l = 0; l < N; ++l) {
          auto& s = b[l];
          s.dt = dt;
          im[l] = s.im = Real(std::pow(10.0, exponent(rng)));
          s.m = 1 / s.im;
          rad[l] = Real(std::pow(10.0, exponent(rng) / 2));
          s.inertia = 1 / (Real(2.5) * s.im / (rad[l] * rad[l]));
          vx[l] = s.vx = value(), vy[l] = s.vy = value(), vz[l] = s.vz = value();
          fx[l] = s.fx = value(), fy[l] = s.fy = value(), fz[l] = s.fz = value();
          wx[l] = s.wx = value(), wy[l] = s.wy = value(), wz[l] = s.wz = value();
          tx[l] = s.tx = value(), ty[l] = s.ty = value(), tz[l] = s.tz = value();
        }
        const LinearDamping::Coeffs<Real> lin{nu, Real(0.01), Real(-0.02), Real(0), limit};
        const RotationalDamping::Coeffs<Real> rot{nu, limit};
        BodyArrays<Real> a;
        a.n = N, a.dt = dt, a.im = im.data(), a.radius = rad.data();
        a.vx = vx.data(), a.vy = vy.data(), a.vz = vz.data(), a.wx = wx.data(), a.wy = wy.data(),
        a.wz = wz.data();
        a.fx = fx.data(), a.fy = fy.data(), a.fz = fz.data(), a.tx = tx.data(), a.ty = ty.data(),
        a.tz = tz.data();
        a.flag = flag.data();
        a.dissipated = lin_out.data();
        LinearDamping::apply_all(lin, a);
        a.dissipated = rot_out.data();
        RotationalDamping::apply_all(rot, a);
        for (std::size_t l = 0; l < N; ++l) {
          const auto& st = b[l];
          BodyForce<Real> f, g;
          LinearDamping::apply(lin, st, f);
          RotationalDamping::apply(rot, st, g);
          EXPECT_EQ(fx[l], st.fx + f.fx);
          EXPECT_EQ(fy[l], st.fy + f.fy);
          EXPECT_EQ(fz[l], st.fz + f.fz);
          EXPECT_EQ(lin_out[l], f.dissipated);
          EXPECT_EQ(tx[l], st.tx + g.tx);
          EXPECT_EQ(ty[l], st.ty + g.ty);
          EXPECT_EQ(tz[l], st.tz + g.tz);
          EXPECT_EQ(rot_out[l], g.dissipated);
          beyond_two += flag[l];
          if (limit > 0) (f.fx == 0 && f.fy == 0 && f.fz == 0 ? zeroed : damped) += 1;
        }
      }
  EXPECT_GT(beyond_two, 50);  // the scalar path is taken too
  // Both outcomes of the iteration limit occur in the sample.
  EXPECT_GT(zeroed, 100);
  EXPECT_GT(damped, 100);
}

TEST(Damping, AllAtOnceMatchesTheScalarFormBitForBit) { all_at_once_matches_the_scalar_form<double>(); }

// In float the vector loop tests "iterate again" in float (a loop of floats vectorises; the scalar form
// converts to double): the same decisions, so the same forces bit for bit.
TEST(Damping, AllAtOnceMatchesTheScalarFormBitForBitInFloat) { all_at_once_matches_the_scalar_form<float>(); }

// kFloatGo is esys_velocity's threshold for a float error e: double(e)^2 > 1e-12 (exact: a float's square
// fits a double) exactly from kFloatGo up.
TEST(Damping, FloatStopIsEsysStop) {
  const float go = LinearDamping::kFloatGo, below = std::nextafter(go, 0.0f);
  EXPECT_GT(double(go) * double(go), 1e-12);
  EXPECT_LE(double(below) * double(below), 1e-12);
}
