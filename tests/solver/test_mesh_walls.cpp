// Mesh walls ([[mesh_walls]], mesh_wall_driver.hpp) in whole runs:
// - a sphere on a flat mesh floor (2 triangles, and a 4x4 grid of 32) under gravity, resting, sliding
//   and rolling with friction along and across shared edges and through shared vertices: the same
//   positions and forces as on a planar wall (elastic 1e-12, frictional 1e-10), every step;
// - a sphere bouncing in a closed one-sided cube (12 triangles, normals inward) stays inside, with its
//   energy conserved;
// - a rotating paddle pushes a resting sphere: the sphere leaves at about twice the paddle's speed, the
//   work the paddle put in (wall_work_in, from the contact-point velocities) equals the kinetic energy,
//   the mesh's force tally is minus the sphere's force;
// - a frictional floor translating under a resting sphere drags it to 2/7 of the floor's speed (the
//   wall velocity enters the friction);
// - a few hundred frictional rotating spheres poured into the silo (scenes/meshes/silo.stl): the same
//   kinetic energies on 2 ranks as on 1 (1e-9), some falling through the orifice (mass_below);
// - scene errors name the file, line and key.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <string>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;
namespace fs = std::filesystem;

namespace {

using V3 = std::array<double, 3>;
using T3 = std::array<int, 3>;

void write_obj(const fs::path& file, const std::vector<V3>& v, const std::vector<T3>& t) {
  std::ofstream out(file);
  out.precision(17);
  for (const auto& x : v) out << "v " << x[0] << " " << x[1] << " " << x[2] << "\n";
  for (const auto& f : t) out << "f " << f[0] + 1 << " " << f[1] + 1 << " " << f[2] + 1 << "\n";
}

/// The square [-h, h]^2 at z = 0 as an n x n grid of quads, each split along its (+1, +1) diagonal,
/// wound counter-clockwise seen from above.
void write_floor(const fs::path& file, int n, double h) {
  std::vector<V3> v;
  std::vector<T3> t;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) v.push_back({-h + 2 * h * i / n, -h + 2 * h * j / n, 0.0});
  const auto at = [n](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      t.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      t.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  write_obj(file, v, t);
}

/// The cube [0, L]^3 from 12 triangles, each wound so that its normal points into the cube.
void write_box(const fs::path& file, double L) {
  std::vector<V3> v;
  for (int k = 0; k < 8; ++k) v.push_back({L * (k & 1), L * ((k >> 1) & 1), L * ((k >> 2) & 1)});
  const int quads[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  std::vector<T3> t;
  for (const auto& q : quads)
    for (const T3 tri : {T3{q[0], q[1], q[2]}, T3{q[0], q[2], q[3]}}) {
      const auto& a = v[static_cast<std::size_t>(tri[0])];
      const auto& b = v[static_cast<std::size_t>(tri[1])];
      const auto& c = v[static_cast<std::size_t>(tri[2])];
      const V3 e1{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const V3 n{e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      const double in = n[0] * (L / 2 - a[0]) + n[1] * (L / 2 - a[1]) + n[2] * (L / 2 - a[2]);
      t.push_back(in > 0 ? tri : T3{tri[0], tri[2], tri[1]});
    }
  write_obj(file, v, t);
}

const std::string kFloorRun = R"(
[particles]
rotation = true
[run]
dt = 5e-4
steps = 0
skin = 0.05
[[body_forces]]
type = "gravity"
acceleration = [0.0, 0.0, -1.0]
)";

std::string floor_wall(bool mesh, const fs::path& file, bool friction) {
  std::string s = mesh ? "[[mesh_walls]]\nname = \"floor\"\nfile = \"" + file.string() + "\"\n"
                       : "[[walls]]\nname = \"floor\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n";
  s += friction ? "interaction = \"friction\"\nK = 1.0e4\nKs = 1.0e4\nmu = 0.2\n" : "K = 1.0e4\n";
  return s;
}

struct Launch {
  V3 x, v;
};

/// Contacts that slid at the last step, over every force compute of a run.
std::size_t sliding_contacts(const Simulation<double>& s) {
  std::size_t n = 0;
  for (const auto& c : s.force_computes()) n += c->sliding_contacts();
  return n;
}

/// Runs the sphere on the planar floor and on the mesh floor side by side; returns the largest
/// position and force differences over the run. Both must count the same sliding contacts at every step.
std::pair<double, double> floor_difference(const fs::path& mesh, bool friction, const Launch& l, int steps) {
  const auto planar_scene = basalt::test::scene_from(kFloorRun + floor_wall(false, mesh, friction));
  const auto mesh_scene = basalt::test::scene_from(kFloorRun + floor_wall(true, mesh, friction));
  const double R = 0.5, m = 4.0 / 3.0 * std::numbers::pi * R * R * R;
  basalt::io::Geometry geo;
  geo.add_particle(1, {l.x[0], l.x[1], R - m / 1e4}, R);  // resting: overlap m g / K
  Simulation<double> a(planar_scene, geo, MPI_COMM_SELF, basalt::test::quiet());
  Simulation<double> b(mesh_scene, geo, MPI_COMM_SELF, basalt::test::quiet());
  for (auto* s : {&a, &b}) {
    auto& p = s->particles();
    p.vx[0] = l.v[0], p.vy[0] = l.v[1], p.vz[0] = l.v[2];
    s->state_changed();
  }
  double dx = 0, df = 0;
  int slid = 0, sliding_differs = 0;
  for (int k = 0; k < steps; ++k) {
    a.step();
    b.step();
    slid += sliding_contacts(a) > 0;
    sliding_differs += sliding_contacts(a) != sliding_contacts(b);
    const auto &p = a.particles(), &q = b.particles();
    dx = std::max({dx, std::abs(p.x[0] - q.x[0]), std::abs(p.y[0] - q.y[0]), std::abs(p.z[0] - q.z[0])});
    df =
        std::max({df, std::abs(p.fx[0] - q.fx[0]), std::abs(p.fy[0] - q.fy[0]), std::abs(p.fz[0] - q.fz[0])});
    if (friction)
      dx = std::max(
          {dx, std::abs(p.wx[0] - q.wx[0]), std::abs(p.wy[0] - q.wy[0]), std::abs(p.wz[0] - q.wz[0])});
  }
  EXPECT_EQ(sliding_differs, 0) << "sliding contacts of the mesh floor and the planar floor (" << slid
                                << " steps sliding)";
  // The mesh's force tally is the planar wall's.
  const auto& fa = a.walls().force(0);
  const auto& fb = b.walls().mesh_force(0);
  for (int d = 0; d < 3; ++d) df = std::max(df, std::abs(fa[d] - fb[d]));
  return {dx, df};
}

}  // namespace

TEST(MeshWalls, FlatMeshFloorIsThePlanarWall) {
  const auto dir = basalt::test::scratch_dir("mesh-walls-floor");
  if (basalt::test::rank() != 0) return;
  write_floor(dir / "two.obj", 1, 4.0);
  write_floor(dir / "grid.obj", 4, 4.0);
  // Resting; sliding/rolling along the diagonal edges through the vertices (0,0) and (2,2); along
  // the grid line y = 0 (edges and vertices all the way); across edges at y = 0.3; from rest at a vertex.
  const Launch launches[] = {{{0.3, -0.2, 0}, {0, 0, 0}},
                             {{-3, -3, 0}, {0.8, 0.8, 0}},
                             {{-3, 0, 0}, {1.2, 0, 0}},
                             {{-3, 0.3, 0}, {1.1, 0.05, 0}},
                             {{0, 0, 0}, {0, 0, 0}}};
  for (const char* mesh : {"two.obj", "grid.obj"})
    for (const bool friction : {false, true})
      for (const auto& l : launches) {
        const auto [dx, df] = floor_difference(dir / mesh, friction, l, 8000);
        std::printf("%s %s from (%g, %g): max |dx| %.3g, max |dF| %.3g\n", mesh,
                    friction ? "friction" : "elastic", l.x[0], l.x[1], dx, df);
        const double tol = friction ? 1e-10 : 1e-12;
        EXPECT_LT(dx, tol) << mesh << (friction ? " friction" : " elastic") << " from " << l.x[0] << ","
                           << l.x[1];
        EXPECT_LT(df, tol * 1e3) << "forces (magnitude ~0.5, K = 1e4)";
      }
}

TEST(MeshWalls, SphereStaysInsideAClosedOneSidedBox) {
  const auto dir = basalt::test::scratch_dir("mesh-walls-box");
  if (basalt::test::rank() != 0) return;
  write_box(dir / "box.obj", 4.0);
  const auto scene = basalt::test::scene_from(R"(
[run]
dt = 5e-4
steps = 0
skin = 0.05
[[mesh_walls]]
name = "box"
file = ")" + (dir / "box.obj").string() + R"("
sides = "one"
K = 1.0e4
[[body_forces]]
type = "gravity"
acceleration = [0.0, 0.0, -1.0]
[[output.fields]]
type = "total_energy"
[[output.fields]]
type = "wall_force"
wall = "box"
)");
  basalt::io::Geometry geo;
  geo.add_particle(1, {2, 2, 3}, 0.5);
  Simulation<double> sim(scene, geo, MPI_COMM_SELF, basalt::test::quiet());
  auto& p = sim.particles();
  p.vx[0] = 3, p.vy[0] = 2.2, p.vz[0] = -1;
  sim.state_changed();
  basalt::test::MemorySink sink(scene);
  double lo = 1e9, hi = -1e9;
  int bounces = 0;
  double last_vx = p.vx[0];
  for (int k = 0; k < 20000; ++k) {
    sim.step(&sink);
    for (const double x : {p.x[0], p.y[0], p.z[0]}) lo = std::min(lo, x), hi = std::max(hi, x);
    if ((p.vx[0] > 0) != (last_vx > 0)) ++bounces;
    last_vx = p.vx[0];
  }
  const auto e = sink.column(0);
  std::printf("centre within [%.4f, %.4f], %d bounces off the x walls, energy %.8g -> %.8g\n", lo, hi,
              bounces, e.front(), e.back());
  // Overlaps up to v sqrt(m / K) = 0.03 at the walls; a sphere escaping would be far out.
  EXPECT_GT(lo, 0.5 - 0.05);
  EXPECT_LT(hi, 3.5 + 0.05);
  EXPECT_GE(bounces, 10);
  EXPECT_NEAR(e.back(), e.front(), 1e-3 * e.front());
  ASSERT_EQ(sink.columns.size(), 4u);
  EXPECT_EQ(sink.columns[1], "wall_force_box_x");
}

TEST(MeshWalls, RotatingPaddlePushesASphere) {
  const auto dir = basalt::test::scratch_dir("mesh-walls-paddle");
  if (basalt::test::rank() != 0) return;
  // A paddle in the plane y = 0, x in [0, 3], z in [-1, 1], turning about the z axis at omega = 1.
  write_obj(dir / "paddle.obj", {{0, 0, -1}, {3, 0, -1}, {3, 0, 1}, {0, 0, 1}}, {{0, 1, 2}, {0, 2, 3}});
  const auto scene = basalt::test::scene_from(R"(
[run]
dt = 2e-4
steps = 0
skin = 0.05
[[mesh_walls]]
name = "paddle"
file = ")" + (dir / "paddle.obj").string() + R"("
K = 1.0e4
[mesh_walls.motion]
rotation = {axis = [0.0, 0.0, 2.0], point = [0.0, 0.0, 0.0], angular_velocity = 1.0}
[[output.fields]]
type = "kinetic_energy"
[[output.fields]]
type = "wall_work_in"
)");
  basalt::io::Geometry geo;
  geo.add_particle(1, {2.0, 1.2, 0.0}, 0.5);
  Simulation<double> sim(scene, geo, MPI_COMM_SELF, basalt::test::quiet());
  basalt::test::MemorySink sink(scene);
  const auto& p = sim.particles();
  double tally = 0;  // largest |mesh force + sphere force|
  bool touched = false;
  for (int k = 0; k < 10000; ++k) {
    sim.step(&sink);
    const auto& f = sim.walls().mesh_force(0);
    tally = std::max({tally, std::abs(f[0] + p.fx[0]), std::abs(f[1] + p.fy[0]), std::abs(f[2] + p.fz[0])});
    touched = touched || f[0] != 0 || f[1] != 0;
  }
  const double speed = std::hypot(p.vx[0], p.vy[0]);
  const double r0 = std::hypot(2.0, 1.2);
  const double ke = sink.column(0).back(), work = sink.column(1).back();
  // Tangential (counter-clockwise) direction at the sphere's start.
  const double vt = (-1.2 * p.vx[0] + 2.0 * p.vy[0]) / r0;
  std::printf("sphere speed %.4f (paddle speed there %.4f), tangential %.4f; KE %.6g, paddle work %.6g\n",
              speed, r0, vt, ke, work);
  EXPECT_TRUE(touched);
  EXPECT_GT(vt, 0.5 * r0) << "pushed the way the paddle turns";
  EXPECT_GT(speed, 1.2 * r0);
  EXPECT_LT(speed, 2.5 * r0);
  EXPECT_NEAR(ke, work, 1e-3 * ke) << "the paddle's work is the sphere's kinetic energy";
  EXPECT_LT(tally, 1e-12);
  EXPECT_NEAR(p.z[0], 0.0, 1e-12);
}

TEST(MeshWalls, TranslatingFrictionalFloorDragsASphereToTwoSevenths) {
  const auto dir = basalt::test::scratch_dir("mesh-walls-belt");
  if (basalt::test::rank() != 0) return;
  write_floor(dir / "belt.obj", 4, 50.0);
  const auto scene = basalt::test::scene_from(kFloorRun + R"(
[[mesh_walls]]
name = "belt"
file = ")" + (dir / "belt.obj").string() + R"("
interaction = "friction"
K = 1.0e4
Ks = 1.0e4
mu = 0.3
[mesh_walls.motion]
type = "constant_velocity"
velocity = [1.0, 0.0, 0.0]
)");
  const double R = 0.5, m = 4.0 / 3.0 * std::numbers::pi * R * R * R;
  basalt::io::Geometry geo;
  geo.add_particle(1, {0.0, 0.0, R - m / 1e4}, R);
  Simulation<double> sim(scene, geo, MPI_COMM_SELF, basalt::test::quiet());
  for (int k = 0; k < 8000; ++k) sim.step();
  const auto& p = sim.particles();
  std::printf("sphere v = %.6f (2/7 = %.6f), w R = %.6f\n", p.vx[0], 2.0 / 7.0, -p.wy[0] * R);
  EXPECT_NEAR(p.vx[0], 2.0 / 7.0, 5e-3);
  EXPECT_NEAR(p.vx[0] - p.wy[0] * R, 1.0, 5e-3) << "rolling without slip on the belt";
}

TEST(MeshWalls, SiloPourIsDecompositionInvariant) {
  const auto silo = basalt::test::source_dir() / "scenes" / "meshes" / "silo.stl";
  const auto scene = basalt::test::scene_from(R"(
[particles]
rotation = true
[run]
dt = 2e-3
steps = 0
skin = 0.2
[[interactions]]
type = "rot_friction"
K = 1.0e4
Ks = 5.0e3
mu = 0.5
mu_dynamic = 0.4
[[mesh_walls]]
name = "silo"
file = ")" + silo.string() + R"("
interaction = "friction"
K = 1.0e4
Ks = 5.0e3
mu = 0.5
[[body_forces]]
type = "gravity"
acceleration = [0.0, 0.0, -10.0]
[[output.fields]]
type = "kinetic_energy"
[[output.fields]]
type = "mass_below"
z = 0.0
[[output.fields]]
type = "wall_force"
wall = "silo"
)");
  // 8 x 8 x 5 grains 2 apart, jittered along x and y by hash_unit(3 id) and (3 id + 1), radii from (3 id +
  // 2).
  const auto g = basalt::test::jittered_lattice(
      {.n = {8, 8, 5}, .origin = {-7.0, -7.0, 2.0}, .spacing = 2.0, .jitter = 0.05, .key = 0},
      [](std::uint64_t u) { return 0.85 + 0.1 * basalt::test::hash_unit(3 * u + 2); }, [](int) { return 0; });
  constexpr int kSteps = 700;
  const auto run = [&](MPI_Comm comm, std::array<int, 3> dims) {
    basalt::test::FieldRun r(scene, g, comm, basalt::test::quiet(dims));
    r.run(kSteps);
    return std::make_tuple(r.sink.column(0), r.sink.column(1), r.sink.column(4), r.sim.rebuilds());
  };
  const int n = basalt::test::size();
  std::vector<double> ref(kSteps);
  if (basalt::test::rank() == 0) {
    auto [ke, below, fz, rebuilds] = run(MPI_COMM_SELF, {1, 1, 1});
    ref = ke;
    std::printf("np 1: KE %.6g, mass below the floor %.4g, silo force z %.4g, %lld rebuilds\n", ke.back(),
                below.back(), fz.back(), static_cast<long long>(rebuilds));
    EXPECT_GT(below.back(), 0.0) << "some spheres fall through the orifice";
    EXPECT_LT(fz.back(), 0.0) << "the spheres on the floor push it down";
    EXPECT_GT(rebuilds, 3);
  }
  MPI_Bcast(ref.data(), kSteps, MPI_DOUBLE, 0, basalt::test::world());
  if (n == 1) return;
  const auto [ke, below, fz, rebuilds] = run(basalt::test::world(), {n, 1, 1});
  if (basalt::test::rank() != 0) return;
  const double worst = basalt::test::worst_relative(ke, ref, 1e-6);
  std::printf("np %d: max relative KE difference %.3g (%lld rebuilds)\n", n, worst,
              static_cast<long long>(rebuilds));
  EXPECT_LT(worst, 1e-9);
}

TEST(MeshWalls, SceneErrorsNameFileLineAndKey) {
  if (basalt::test::rank() != 0) return;
  const auto err = [](const std::string& body) {
    try {
      basalt::test::scene_from("[run]\ndt = 1e-3\nsteps = 1\nskin = 0.1\n" + body);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const auto silo = (basalt::test::source_dir() / "scenes" / "meshes" / "silo.stl").string();
  EXPECT_NE(err("[[mesh_walls]]\nfile = \"nope.stl\"\nK = 1.0\n").find("test.toml:8: mesh_walls[0].file"),
            std::string::npos)
      << err("[[mesh_walls]]\nfile = \"nope.stl\"\nK = 1.0\n");
  EXPECT_NE(err("[[mesh_walls]]\nfile = \"" + silo + "\"\nK = 1.0\nsides = \"three\"\n")
                .find("mesh_walls[0].sides"),
            std::string::npos);
  EXPECT_NE(err("[[mesh_walls]]\nfile = \"" + silo +
                "\"\nK = 1.0\n[mesh_walls.motion]\ntype = \"sine\"\n"
                "amplitude = 1.0\nperiod = 1.0\n")
                .find("mesh_walls[0].motion.direction"),
            std::string::npos);
  EXPECT_NE(
      err("[[mesh_walls]]\nfile = \"" + silo +
          "\"\nK = 1.0\n[mesh_walls.motion]\nrotation = {axis = [0.0, 0.0, 0.0], angular_velocity = 1.0}\n")
          .find("mesh_walls[0].motion.rotation.axis"),
      std::string::npos);
  EXPECT_NE(err("[[mesh_walls]]\nfile = \"" + silo + "\"\nK = 1.0\nscal = 2.0\n").find("mesh_walls[0].scal"),
            std::string::npos);
  EXPECT_NE(err("[[output.fields]]\ntype = \"wall_force\"\nwall = \"silo\"\n")
                .find("no wall named \"silo\" (planar or mesh)"),
            std::string::npos);
  // scale and offset place the mesh; a mesh wall's name is a wall_force target; mass_below takes z.
  const auto s = basalt::test::scene_from(
      "[run]\ndt = 1e-3\nsteps = 1\nskin = 0.1\n[[mesh_walls]]\nname = \"silo\"\n"
      "file = \"" +
      silo +
      "\"\nK = 1.0\nscale = 0.5\noffset = [1.0, 2.0, 3.0]\n"
      "[[output.fields]]\ntype = \"wall_force\"\nwall = \"silo\"\n"
      "[[output.fields]]\ntype = \"mass_below\"\nz = -2.5\n");
  ASSERT_EQ(s.mesh_walls.size(), 1u);
  double zmin = 1e9, zmax = -1e9, xmax = -1e9;
  for (const auto& v : s.mesh_walls[0].vertices)
    zmin = std::min(zmin, v[2]), zmax = std::max(zmax, v[2]), xmax = std::max(xmax, v[0]);
  EXPECT_DOUBLE_EQ(zmin, 3.0);
  EXPECT_DOUBLE_EQ(zmax, 33.0);
  EXPECT_NEAR(xmax, 11.0, 1e-9);
  ASSERT_EQ(s.fields.size(), 2u);
  EXPECT_EQ(s.fields[1].type, FieldSpec::Type::mass_below);
  EXPECT_EQ(s.fields[1].z, -2.5);
  EXPECT_EQ(field_columns(s).back(), "mass_below");
}
