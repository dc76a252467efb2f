// Walls that load a specimen (issue 12, "Loading"; issue 11, "Walls"), each against a closed form,
// a conservation law or a decomposition:
// - ramp motion: the position is the exact integral of a speed ramped linearly to V over ramp_time
//   (ESyS's WallLoader ramps over steps: the relation is exact, see RampMatchesESySWallLoader), and
//   the wall_position saver writes it;
// - servo wall: a confined sample is squeezed until the force on the wall is the target (1 %), with
//   the same wall trajectory on 1, 2 and 4 ranks (1e-9);
// - bonded wall (ESyS NRotBondedWall): a particle tied to a wall that starts moving feels
//   F = V sqrt(k m) sin(omega t), the full vector; the ledger's wall_potential_energy plus kinetic
//   energy equals the work the wall did; a sheared layer tied to a wall is decomposition invariant.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <tuple>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/models/bonded_wall.hpp"
#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;

namespace {

/// A box of touching spheres (radius 0.5, spacing 1, jitter 0.01 in x and y), nx x ny x nz, in
/// [0, nx] x [0, ny] x [0, nz]; the top layer tagged 2, the others 0; ids from 1.
basalt::io::Geometry box(int nx, int ny, int nz) {
  return basalt::test::jittered_lattice(
      {.n = {nx, ny, nz}, .jitter = 0.01}, [](std::uint64_t) { return 0.5; },
      [nz](int k) { return k == nz - 1 ? 2 : 0; });
}

std::size_t column_of(const basalt::test::MemorySink& s, const std::string& name) {
  for (std::size_t c = 0; c < s.columns.size(); ++c)
    if (s.columns[c] == name) return c;
  ADD_FAILURE() << "no column " << name;
  return 0;
}

}  // namespace

TEST(RampMotion, PositionIsTheExactIntegralOfTheRampedSpeed) {
  WallMotion m;
  m.type = WallMotion::Type::ramp;
  m.velocity = {0.0, 0.0, -0.03};
  m.ramp_time = 0.1;
  m.start_time = 0.02;
  for (const double t : {0.0, 0.01, 0.02, 0.05, 0.0999, 0.12, 0.5, 3.0}) {
    const double s = t - m.start_time;
    const double ramp = s <= 0 ? 0 : (s < m.ramp_time ? s * s / (2 * m.ramp_time) : s - m.ramp_time / 2);
    const double speed = s <= 0 ? 0 : std::min(s / m.ramp_time, 1.0);
    EXPECT_NEAR(m.displacement_at(t)[2], -0.03 * ramp, 1e-15) << "t = " << t;
    EXPECT_NEAR(m.velocity_at(t)[2], -0.03 * speed, 1e-15) << "t = " << t;
    EXPECT_EQ(m.displacement_at(t)[0], 0.0);
  }
  // The displacement is the integral of the velocity (trapezoids are exact on a piecewise linear
  // speed whose kinks lie on the grid: 0.02 and 0.12 are multiples of h).
  const double h = 1e-4;
  double x = 0;
  for (int k = 0; k < 5000; ++k) {
    x += 0.5 * h * (m.velocity_at(k * h)[2] + m.velocity_at((k + 1) * h)[2]);
    ASSERT_NEAR(x, m.displacement_at((k + 1) * h)[2], 1e-13) << "t = " << (k + 1) * h;
  }
}

TEST(RampMotion, RampMatchesESySWallLoader) {
  // ESyS's WallLoaderRunnable (pre-time-step, Nt counting its calls from 0) moves the wall by f V dt with
  // f = Nt / rampTime while Nt < rampTime, then 1, before the forces of the step: the forces of ESyS's step
  // n + 1, computed from the particles after step n, see V dt sum_{k<=n} min(k / R, 1)
  // (tools/esys/probe_ucs.py, wall_loader). Basalt computes those forces at the end of its step n, with the
  // wall at time n dt: a ramp with ramp_time = R dt and start_time = -dt / 2 is exactly there after the
  // ramp, and V dt / (8 R) further during it. (start_time = +dt / 2 would lag a whole step, V dt.)
  const double dt = 5e-5, V = 0.03;
  const int R = 2000;
  WallMotion m;
  m.type = WallMotion::Type::ramp;
  m.velocity = {0, 0, V};
  m.ramp_time = R * dt;
  m.start_time = -dt / 2;
  double esys = 0;  // the wall the forces of ESyS's step n + 1 see
  for (int n = 0; n <= 3 * R; ++n) {
    esys += V * dt * std::min(double(n) / R, 1.0);
    const double ours = m.displacement_at(n * dt)[2];
    const double expected = n < R ? esys + V * dt / (8.0 * R) : esys;
    ASSERT_NEAR(ours, expected, 1e-12 * V * dt * (n + 1)) << "step " << n;
  }
}

TEST(RampMotion, WallPositionSaverWritesTheRamp) {
  if (basalt::test::rank() != 0) return;
  const auto scene = basalt::test::scene_from(R"(
[run]
dt = 1e-3
steps = 0
skin = 0.1
[[interactions]]
type = "linear_elastic"
K = 1000.0
[[walls]]
name = "platen"
point = [0.0, 0.0, 3.0]
normal = [0.0, 0.0, -1.0]
K = 1000.0
motion = {type = "ramp", velocity = [0.01, 0.0, -0.2], ramp_time = 0.05, start_time = 0.01}
[output]
fields = [{type = "wall_position", wall = "platen"}, {type = "wall_force", wall = "platen"}]
)");
  basalt::io::Geometry g;
  g.add_particle(1, {0.5, 0.5, 0.5}, 0.5, 0);
  const auto opt = basalt::test::quiet();
  Simulation<double> sim(scene, g, MPI_COMM_SELF, opt);
  basalt::test::MemorySink sink(scene);
  ASSERT_EQ(sink.columns[0], "wall_position_platen_x");
  ASSERT_EQ(sink.columns[2], "wall_position_platen_z");
  ASSERT_EQ(sink.columns[3], "wall_force_platen_x");
  sim.run(200, &sink);
  ASSERT_EQ(sink.rows.size(), 200u);
  for (std::size_t r = 0; r < sink.rows.size(); ++r) {
    const double t = sink.times[r];
    const double s = t <= 0.01 ? 0 : (t < 0.06 ? (t - 0.01) * (t - 0.01) / 0.1 : t - 0.01 - 0.025);
    EXPECT_NEAR(*sink.rows[r][0], 0.01 * s, 1e-15);
    EXPECT_NEAR(*sink.rows[r][2], 3.0 - 0.2 * s, 1e-14);
  }
  EXPECT_LT(*sink.rows.back()[2], 3.0 - 0.2 * 0.15) << "the wall moved";
}

namespace {

/// A confined box (4 x 4 x 6, linear elastic contacts, light damping) squeezed by a servo top wall.
const std::string kServoScene = R"(
[run]
dt = 1e-3
steps = 0
skin = 0.1
[[interactions]]
type = "linear_elastic"
K = 1000.0
[[body_forces]]
type = "linear_damping"
viscosity = 2.0
[[walls]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
K = 1000.0
[[walls]]
name = "x0"
point = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
K = 1000.0
[[walls]]
name = "x1"
point = [4.0, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
K = 1000.0
[[walls]]
name = "y0"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
K = 1000.0
[[walls]]
name = "y1"
point = [0.0, 4.0, 0.0]
normal = [0.0, -1.0, 0.0]
K = 1000.0
[[walls]]
name = "top"
point = [0.0, 0.0, 6.0]
normal = [0.0, 0.0, -1.0]
K = 1000.0
motion = {type = "servo", target_stress = 10.0, area = 16.0, gain = 1e-3, max_speed = 0.05}
[output]
fields = [{type = "wall_position", wall = "top"}, {type = "wall_force", wall = "top"},
          {type = "wall_force", wall = "floor"}]
)";

}  // namespace

TEST(ServoWall, HoldsTheTargetForceOnAConfinedBoxOnAnyNumberOfRanks) {
  const auto scene = basalt::test::scene_from(kServoScene);
  ASSERT_DOUBLE_EQ(scene.walls[5].motion.servo.target_force, 160.0) << "target_stress x area";
  const auto g = box(4, 4, 6);
  constexpr int kSteps = 6000;
  const auto run = [&](MPI_Comm comm, std::array<int, 3> dims) {
    return basalt::test::run_fields(scene, g, comm, kSteps, dims);
  };
  const int n = basalt::test::size();
  std::vector<double> ref_z(kSteps), ref_f(kSteps);
  if (basalt::test::rank() == 0) {
    const auto s = run(MPI_COMM_SELF, {1, 1, 1});
    ref_z = s.column(column_of(s, "wall_position_top_z"));
    ref_f = s.column(column_of(s, "wall_force_top_z"));
    const auto floor = s.column(column_of(s, "wall_force_floor_z"));
    // The particles push the top wall up (+z) with the target force; the floor carries the same load.
    std::printf(
        "servo: top wall at z = %.6f (moved %.4f), force on it %.4f (target 160), on the floor %.4f\n",
        ref_z.back(), 6.0 - ref_z.back(), ref_f.back(), -floor.back());
    EXPECT_NEAR(ref_f.back(), 160.0, 1.6) << "within 1 % of the target";
    EXPECT_NEAR(-floor.back(), 160.0, 1.6) << "the sample is in equilibrium";
    EXPECT_LT(ref_z.back(), 6.0 - 0.02) << "the wall moved in to load the sample";
    double peak = 0;
    for (double f : ref_f) peak = std::max(peak, f);
    EXPECT_LT(peak, 1.25 * 160.0) << "no large overshoot (max " << peak << ")";
    // Held, not passing through: over the last 1000 steps the force stays within 1 %.
    for (int k = kSteps - 1000; k < kSteps; ++k) ASSERT_NEAR(ref_f[static_cast<std::size_t>(k)], 160.0, 1.6);
  }
  MPI_Bcast(ref_z.data(), kSteps, MPI_DOUBLE, 0, basalt::test::world());
  MPI_Bcast(ref_f.data(), kSteps, MPI_DOUBLE, 0, basalt::test::world());
  if (n == 1) return;
  std::vector<std::array<int, 3>> grids{{1, 1, n}};  // 4 ranks along x would be thinner than the ghosts
  grids.push_back(n == 2 ? std::array<int, 3>{2, 1, 1} : std::array<int, 3>{2, 2, 1});
  for (const auto& dims : grids) {
    const auto s = run(basalt::test::world(), dims);
    if (basalt::test::rank() != 0) continue;
    const auto z = s.column(column_of(s, "wall_position_top_z"));
    const auto f = s.column(column_of(s, "wall_force_top_z"));
    double worst_z = 0, worst_f = 0;
    for (std::size_t k = 0; k < z.size(); ++k) {
      worst_z = std::max(worst_z, std::abs(z[k] - ref_z[k]) / std::abs(ref_z[k]));
      if (std::abs(ref_f[k]) > 1e-3) worst_f = std::max(worst_f, std::abs(f[k] - ref_f[k]) / 160.0);
    }
    std::printf("np %d dims %d,%d,%d: servo wall position %.3g, force %.3g (relative, worst step)\n", n,
                dims[0], dims[1], dims[2], worst_z, worst_f);
    EXPECT_LT(worst_z, 1e-9);
    EXPECT_LT(worst_f, 1e-9);
  }
}

TEST(ServoWall, BadKeysAreRefusedWithTheirName) {
  const auto fails = [](const std::string& motion, const std::string& what) {
    try {
      basalt::test::scene_from(
          "[run]\ndt = 1e-3\nsteps = 1\nskin = 0.1\n[[walls]]\npoint = [0.0, 0.0, 0.0]\n"
          "normal = [0.0, 0.0, 1.0]\nK = 1.0\nmotion = {" +
          motion + "}\n");
      ADD_FAILURE() << "accepted: " << motion;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  fails(R"(type = "servo", gain = 1.0, max_speed = 1.0)", "walls[0].motion.target_force: missing");
  fails(R"(type = "servo", target_force = 1.0, target_stress = 1.0, area = 1.0, gain = 1.0, max_speed = 1.0)",
        "not both");
  fails(R"(type = "servo", target_stress = 1.0, gain = 1.0, max_speed = 1.0)", "walls[0].motion.area");
  fails(R"(type = "servo", target_force = 1.0, gain = -1.0, max_speed = 1.0)", "walls[0].motion.gain");
  fails(R"(type = "ramp", velocity = [0.0, 0.0, 1.0])", "walls[0].motion.ramp_time");
}

namespace {

/// One particle (radius 0.5, density 1) tied to a wall z = 0 that moves at V = (vx, 0, vz) from t = 0.
std::string bonded_one(const std::string& stiffness) {
  return R"(
[run]
dt = 1e-4
steps = 0
skin = 0.1
energy_check_every = 0
[[walls]]
name = "grip"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
interaction = "bonded"
K = 100.0
stiffness = ")" +
         stiffness +
         R"("
bond_tags = [2]
motion = {type = "constant_velocity", velocity = [0.02, 0.0, 0.01]}
[output]
fields = [{type = "wall_force", wall = "grip"}, {type = "kinetic_energy"}, {type = "wall_potential_energy"}]
)";
}

}  // namespace

TEST(BondedWall, ForceOnATiedParticleFollowsTheClosedFormAndTheLedgerBalances) {
  if (basalt::test::rank() != 0) return;
  for (const std::string stiffness : {"plain", "esys_pi_r"}) {
    const auto scene = basalt::test::scene_from(bonded_one(stiffness));
    basalt::io::Geometry g;
    g.add_particle(1, {0.3, -0.2, 0.25}, 0.5, 2);  // overlapping the wall: tied, not repelled
    const auto opt = basalt::test::quiet();
    Simulation<double> sim(scene, g, MPI_COMM_SELF, opt);
    const double m = 4.0 / 3.0 * std::numbers::pi * 0.125;
    const double k = stiffness == "plain" ? 100.0 : BondedWall::kEsysBondPi * 0.5 * 100.0;
    const double w = std::sqrt(k / m);
    basalt::test::MemorySink sink(scene);
    const int steps = static_cast<int>(3 * 2 * std::numbers::pi / w / 1e-4);  // three periods
    sim.run(steps, &sink);
    // Relative coordinate u = x - x0 - V t: m u'' = -k u, u(0) = 0, u'(0) = -V, so the particle feels
    // F = -k u = V sqrt(k m) sin(w t) along V (both components: the spring is a full vector) and the
    // wall the opposite.
    double worst = 0, work = 0, worst_balance = 0, emax = 0;
    double prev_power = 0;
    const std::array<double, 3> V{0.02, 0.0, 0.01};
    for (std::size_t r = 0; r < sink.rows.size(); ++r) {
      const double t = sink.times[r];
      const double amp = std::sqrt(k * m) * std::sin(w * t);
      for (int d = 0; d < 3; ++d)
        worst = std::max(worst, std::abs(*sink.rows[r][static_cast<std::size_t>(d)] + V[d] * amp) /
                                    (std::sqrt(k * m) * 0.02));
      // The wall's power -F_wall . V, integrated (trapezoids); the particle starts at rest, unloaded.
      const double power = -(*sink.rows[r][0] * V[0] + *sink.rows[r][2] * V[2]);
      work += 0.5 * 1e-4 * (prev_power + power);
      prev_power = power;
      const double e = *sink.rows[r][3] + *sink.rows[r][4];
      emax = std::max(emax, e);
      worst_balance = std::max(worst_balance, std::abs(e - work));
    }
    std::printf(
        "bonded wall (%s, k = %.6g): force vs V sqrt(k m) sin(w t): %.3g of its amplitude; "
        "kinetic + wall potential - work: %.3g of the largest energy %.4g\n",
        stiffness.c_str(), k, worst, worst_balance / emax, emax);
    EXPECT_LT(worst, 2e-3) << "velocity Verlet's phase error at w dt = " << w * 1e-4;
    EXPECT_LT(worst_balance, 1e-3 * emax);
    const auto pot = sink.column(4);
    EXPECT_GT(*std::max_element(pot.begin(), pot.end()), 0.2 * emax) << "the spring stores energy";
  }
}

TEST(BondedWall, ShearedLayerTiedToAWallIsDecompositionInvariant) {
  // The top layer (tag 2) of a 6 x 2 x 3 box is tied to the wall above it, which ramps up to a shear
  // speed along x: the layer slides over the one below it across rank boundaries (migration carries
  // its rest offsets), a floor wall and the box's other particles repel it elastically.
  const auto scene = basalt::test::scene_from(R"(
[run]
dt = 1e-3
steps = 0
skin = 0.1
[[interactions]]
type = "linear_elastic"
K = 1000.0
[[walls]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
K = 1000.0
[[walls]]
name = "grip"
point = [0.0, 0.0, 3.0]
normal = [0.0, 0.0, -1.0]
interaction = "bonded"
K = 500.0
bond_tags = [2]
motion = {type = "ramp", velocity = [0.5, 0.0, -0.02], ramp_time = 0.5}
[output]
fields = [{type = "wall_force", wall = "grip"}, {type = "kinetic_energy"}]
)");
  const auto g = box(6, 2, 3);
  constexpr int kSteps = 3000;  // the layer travels 1.25, more than a rank's width at np 4 along x
  const auto run = [&](MPI_Comm comm, std::array<int, 3> dims) {
    basalt::test::FieldRun r(scene, g, comm, basalt::test::quiet(dims));
    r.run(kSteps);
    double dx = 0;  // the tied layer's mean displacement along x (this rank's particles)
    int tied = 0;
    const auto& p = r.sim.particles();
    for (std::size_t i = 0; i < p.n_owned; ++i)
      if (p.tag[i] == 2) {
        dx += p.x[i] - g.position[static_cast<std::size_t>(g.index_of(p.id[i]))][0];
        ++tied;
      }
    return std::make_tuple(r.sink, r.sim.rebuilds(), tied ? dx / tied : 0.0);
  };
  const int n = basalt::test::size();
  std::vector<double> ref(3 * kSteps);
  if (basalt::test::rank() == 0) {
    const auto [s, rebuilds, dx] = run(MPI_COMM_SELF, {1, 1, 1});
    for (int c = 0; c < 3; ++c) {
      const auto col = s.column(static_cast<std::size_t>(c));
      std::copy(col.begin(), col.end(), ref.begin() + c * kSteps);
    }
    EXPECT_GT(rebuilds, 5);
    const double wall_dx = 0.5 * (kSteps * 1e-3 - 0.25);  // the ramp's closed form
    std::printf("sheared layer: moved %.4f along x with the wall's %.4f\n", dx, wall_dx);
    EXPECT_NEAR(dx, wall_dx, 0.05) << "the tied layer follows the wall";
  }
  MPI_Bcast(ref.data(), 3 * kSteps, MPI_DOUBLE, 0, basalt::test::world());
  if (n == 1) return;
  double scale = 0;
  for (double v : ref) scale = std::max(scale, std::abs(v));
  std::vector<std::array<int, 3>> grids{{n, 1, 1}};
  if (n == 4) grids.push_back({2, 1, 2});
  for (const auto& dims : grids) {
    const auto [s, rebuilds, dx] = run(basalt::test::world(), dims);
    if (basalt::test::rank() != 0) continue;
    double worst = 0;
    for (int c = 0; c < 3; ++c) {
      const auto col = s.column(static_cast<std::size_t>(c));
      for (int k = 0; k < kSteps; ++k)
        worst = std::max(worst, std::abs(col[static_cast<std::size_t>(k)] -
                                         ref[static_cast<std::size_t>(c * kSteps + k)]));
    }
    std::printf(
        "np %d dims %d,%d,%d: bonded wall force, worst difference %.3g of its largest %.4g (%lld rebuilds)\n",
        n, dims[0], dims[1], dims[2], worst / scale, scale, static_cast<long long>(rebuilds));
    EXPECT_LT(worst, 1e-9 * scale);
  }
}

TEST(BondedWall, RefusedOnMeshWallsAndWithoutBondTags) {
  try {
    basalt::test::scene_from(
        "[run]\ndt = 1e-3\nsteps = 1\nskin = 0.1\n[[walls]]\npoint = [0.0, 0.0, 0.0]\n"
        "normal = [0.0, 0.0, 1.0]\ninteraction = \"bonded\"\nK = 1.0\n");
    ADD_FAILURE() << "accepted a bonded wall without bond_tags";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("walls[0].bond_tags: missing"), std::string::npos) << e.what();
  }
}
