// Sphere contacts with triangle meshes (ContactMesh): one plane contact on a flat mesh wherever the
// sphere is (face, shared edge, shared vertex); one contact at a convex edge or vertex; one per face in a
// concave corner; moving meshes; the cell grid against brute force; the shipped silo.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "basalt/io/mesh_file.hpp"
#include "basalt/solver/geometry/triangle_mesh.hpp"
#include "test_support.hpp"

using basalt::solver::ContactMesh;
using basalt::solver::MeshContact;
using basalt::solver::MeshFeature;
using basalt::solver::RigidTransform;
using Vec3 = ContactMesh::Vec3;
using Tri = ContactMesh::Triangle;

namespace {

/// An nx x ny grid of unit squares in z = 0, each split in two along an alternating diagonal (so interior
/// vertices have 4, 6 or 8 triangles), mapped by `map` (identity by default).
template <class Map>
ContactMesh flat_grid(int nx, int ny, Map map, ContactMesh::Options opt = {}) {
  std::vector<Vec3> v;
  std::vector<Tri> t;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) v.push_back(map(Vec3{double(i), double(j), 0}));
  auto id = [&](int i, int j) { return static_cast<std::int32_t>(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const auto a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if ((i + j) % 2 == 0)
        t.push_back({a, b, c}), t.push_back({a, c, d});
      else
        t.push_back({a, b, d}), t.push_back({b, c, d});
    }
  return ContactMesh(v, t, opt);
}
ContactMesh flat_grid(int nx, int ny, ContactMesh::Options opt = {}) {
  return flat_grid(
      nx, ny, [](const Vec3& x) { return x; }, opt);
}

Vec3 sum_force(const std::vector<MeshContact>& cs) {
  Vec3 s{0, 0, 0};
  for (const auto& c : cs)
    for (int d = 0; d < 3; ++d) s[d] += c.overlap * c.normal[d];
  return s;
}

void expect_near(const Vec3& a, const Vec3& b, double tol) {
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(a[d], b[d], tol) << "component " << d;
}

/// The unit cube [0, 1]^3, 12 triangles wound counter-clockwise seen from outside.
ContactMesh cube(ContactMesh::Options opt = {}) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i) v.push_back({double(i & 1), double(i >> 1 & 1), double(i >> 2 & 1)});
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<Tri> t;
  for (const auto& q : quads) t.push_back({q[0], q[1], q[2]}), t.push_back({q[0], q[2], q[3]});
  return ContactMesh(v, t, opt);
}

/// Reproducible uniform doubles in [0, 1) (no std::uniform_real_distribution: it differs between libraries).
struct Uniform {
  std::mt19937_64 engine;
  explicit Uniform(std::uint64_t seed) : engine(seed) {}
  double operator()() { return static_cast<double>(engine() >> 11) * 0x1.0p-53; }
};

/// Positions along a path across [0, n]^2 that hit every vertex and every edge exactly (steps of 1/16),
/// along rows, columns and both diagonals, plus seeded random points.
std::vector<std::array<double, 2>> rolling_path(int n) {
  std::vector<std::array<double, 2>> p;
  const int steps = 16 * n;
  for (double y : {0.0, 0.25, 0.5, 1.0, 1.0 / 3.0, double(n) / 2, double(n)})
    for (int k = 0; k <= steps; ++k) p.push_back({k / 16.0, std::min(y, double(n))});
  for (int k = 0; k <= steps; ++k) p.push_back({0.5, k / 16.0}), p.push_back({double(n), k / 16.0});
  for (int k = 0; k <= steps; ++k) p.push_back({k / 16.0, k / 16.0}), p.push_back({k / 16.0, n - k / 16.0});
  Uniform u(12345);
  for (int k = 0; k < 500; ++k) p.push_back({n * u(), n * u()});
  return p;
}

void roll_on_flat(const ContactMesh& mesh, int n, double r, double h) {
  std::vector<MeshContact> cs;
  for (const auto& xy : rolling_path(n)) {
    cs.clear();
    mesh.contacts({xy[0], xy[1], h}, r, cs);
    SCOPED_TRACE(testing::Message() << "centre (" << xy[0] << ", " << xy[1] << ", " << h << ")");
    ASSERT_EQ(cs.size(), 1u);
    expect_near(sum_force(cs), {0, 0, h > 0 ? r - h : -(r + h)}, 1e-12);  // pushed away from its side
    expect_near(cs[0].point, {xy[0], xy[1], 0}, 1e-12);
  }
}

}  // namespace

TEST(TriangleMesh, TopologyOfTheCube) {
  const auto m = cube();
  EXPECT_EQ(m.num_vertices(), 8u);
  EXPECT_EQ(m.num_triangles(), 12u);
  EXPECT_EQ(m.num_edges(), 18u);  // 12 cube edges + 6 face diagonals
  EXPECT_EQ(m.boundary_edges(), 0u);
  EXPECT_EQ(m.nonmanifold_edges(), 0u);
  for (std::size_t e = 0; e < m.num_edges(); ++e) EXPECT_EQ(m.edge_triangles(e).size(), 2u);
  std::size_t incidences = 0;
  for (std::size_t v = 0; v < m.num_vertices(); ++v) incidences += m.vertex_triangles(v).size();
  EXPECT_EQ(incidences, 36u);
  EXPECT_THROW(ContactMesh({{0, 0, 0}, {1, 0, 0}}, {{0, 1, 2}}), std::invalid_argument);
  EXPECT_THROW(ContactMesh({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {{0, 1, 2}}), std::invalid_argument);
}

TEST(TriangleMesh, RollingAcrossTwoTrianglesIsOnePlaneContact) {
  const auto m = flat_grid(1, 1);
  ASSERT_EQ(m.num_triangles(), 2u);
  roll_on_flat(m, 1, 0.5, 0.3);
  roll_on_flat(m, 1, 0.5, -0.3 + 1e-3);  // from below (two-sided)
}

TEST(TriangleMesh, RollingAcrossAFourByFourGridIsOnePlaneContact) {
  const auto m = flat_grid(4, 4);
  ASSERT_EQ(m.num_triangles(), 32u);
  for (double h : {0.4, 0.1, 1e-6}) roll_on_flat(m, 4, 0.5, h);
  roll_on_flat(m, 4, 2.5, 1.5);  // a sphere larger than the triangles touches many of them
  ContactMesh::Options one;
  one.sides = ContactMesh::Sides::one;
  roll_on_flat(flat_grid(4, 4, one), 4, 0.5, 0.2);
}

TEST(TriangleMesh, RollingOnATiltedShiftedGridIsOnePlaneContact) {
  // Coordinates not exactly representable: a plane through (0.1, -0.3, 0.7) with normal n.
  const double a = 0.3, b = 0.7;
  const Vec3 e1{std::cos(a), std::sin(a), 0};
  const Vec3 n{std::sin(b) * -std::sin(a), std::sin(b) * std::cos(a), std::cos(b)};
  const Vec3 e2{n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2], n[0] * e1[1] - n[1] * e1[0]};
  const Vec3 o{0.1, -0.3, 0.7};
  auto map = [&](const Vec3& x) {
    Vec3 y;
    for (int d = 0; d < 3; ++d) y[d] = o[d] + x[0] * e1[d] + x[1] * e2[d] + x[2] * n[d];
    return y;
  };
  const auto m = flat_grid(4, 4, map);
  const double r = 0.5;
  std::vector<MeshContact> cs;
  for (double h : {0.3, 1e-4})
    for (const auto& xy : rolling_path(4)) {
      cs.clear();
      m.contacts(map({xy[0], xy[1], h}), r, cs);
      SCOPED_TRACE(testing::Message() << "at (" << xy[0] << ", " << xy[1] << ") h " << h);
      ASSERT_EQ(cs.size(), 1u);
      const auto f = sum_force(cs);
      // The mapped vertices are in the plane only to rounding (~1e-16 x size): over a height h that tilts
      // an edge or vertex contact's normal by ~1e-16 / h, hence the looser bound for the nearly touching
      // sphere.
      expect_near(f, {(r - h) * n[0], (r - h) * n[1], (r - h) * n[2]}, h < 0.01 ? 1e-10 : 1e-12);
    }
}

TEST(TriangleMesh, JustOffAnEdgeOrAVertexIsStillOnePlaneContact) {
  // Centres a tiny distance (1e-15 to 1e-3) from a shared vertex or edge, in 16 directions: where rounding
  // decides between face, edge and vertex. Exact and tilted (inexact) coordinates.
  const double a = 0.4, b = 0.9;
  const Vec3 e1{std::cos(a), std::sin(a), 0};
  const Vec3 n{std::sin(b) * -std::sin(a), std::sin(b) * std::cos(a), std::cos(b)};
  const Vec3 e2{n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2], n[0] * e1[1] - n[1] * e1[0]};
  auto tilt = [&](const Vec3& x) {
    Vec3 y;
    for (int d = 0; d < 3; ++d) y[d] = 3.7 + x[0] * e1[d] + x[1] * e2[d] + x[2] * n[d];
    return y;
  };
  auto flat = [](const Vec3& x) { return x; };
  const auto exact = flat_grid(4, 4, flat), tilted = flat_grid(4, 4, tilt);
  const double r = 0.5, h = 0.25;
  std::vector<MeshContact> cs;
  for (const auto* m : {&exact, &tilted}) {
    const bool is_tilted = m == &tilted;
    for (const auto& base :
         std::vector<std::array<double, 2>>{{2, 2}, {1, 2}, {1, 1}, {2, 1.5}, {1.5, 1.5}, {0.5, 2.5}})
      for (double eps : {1e-15, 1e-13, 1e-12, 1e-11, 1e-10, 1e-9, 1e-8, 1e-6, 1e-3})
        for (int k = 0; k < 16; ++k) {
          const double phi = 2 * M_PI * k / 16 + 0.01;
          const Vec3 local{base[0] + eps * std::cos(phi), base[1] + eps * std::sin(phi), h};
          cs.clear();
          m->contacts(is_tilted ? tilt(local) : local, r, cs);
          SCOPED_TRACE(testing::Message() << (is_tilted ? "tilted" : "exact") << " near (" << base[0] << ", "
                                          << base[1] << ") eps " << eps << " direction " << k);
          ASSERT_EQ(cs.size(), 1u);
          const Vec3 want =
              is_tilted ? Vec3{(r - h) * n[0], (r - h) * n[1], (r - h) * n[2]} : Vec3{0, 0, r - h};
          expect_near(sum_force(cs), want, 1e-12);
        }
  }
}

TEST(TriangleMesh, ConvexEdgeOfACubeIsOneEdgeContact) {
  for (auto sides : {ContactMesh::Sides::two, ContactMesh::Sides::one}) {
    ContactMesh::Options opt;
    opt.sides = sides;
    const auto m = cube(opt);
    std::vector<MeshContact> cs;
    for (double s : {0.34, 0.3, 0.2, 0.1, 0.01}) {  // approaching the edge x = z = 1 along (1, 0, 1)
      for (double y : {0.5, 0.25, 0.9}) {
        cs.clear();
        m.contacts({1 + s, y, 1 + s}, 0.5, cs);
        ASSERT_EQ(cs.size(), 1u) << "s " << s << " y " << y;
        EXPECT_EQ(cs[0].feature, MeshFeature::edge);
        expect_near(cs[0].point, {1, y, 1}, 1e-14);
        expect_near(cs[0].normal, {M_SQRT1_2, 0, M_SQRT1_2}, 1e-14);
        EXPECT_NEAR(cs[0].overlap, 0.5 - s * std::sqrt(2.0), 1e-14);
      }
    }
    cs.clear();
    m.contacts({1.4, 0.5, 1.4}, 0.5, cs);  // out of reach
    EXPECT_TRUE(cs.empty());
    cs.clear();
    m.contacts({0.95, 0.5, 1.3}, 0.5, cs);  // over the top face, near the edge: the face only
    ASSERT_EQ(cs.size(), 1u);
    EXPECT_EQ(cs[0].feature, MeshFeature::face);
    expect_near(cs[0].normal, {0, 0, 1}, 1e-15);
  }
}

TEST(TriangleMesh, VertexOfACubeIsOneVertexContact) {
  const auto m = cube();
  std::vector<MeshContact> cs;
  for (double s : {0.28, 0.2, 0.05}) {
    cs.clear();
    m.contacts({1 + s, 1 + s, 1 + s}, 0.5, cs);
    ASSERT_EQ(cs.size(), 1u);
    EXPECT_EQ(cs[0].feature, MeshFeature::vertex);
    expect_near(cs[0].point, {1, 1, 1}, 0);
    const double k = 1 / std::sqrt(3.0);
    expect_near(cs[0].normal, {k, k, k}, 1e-15);
    EXPECT_NEAR(cs[0].overlap, 0.5 - s * std::sqrt(3.0), 1e-15);
  }
  // The origin corner has 6 incident triangles, (1, 1, 1) 3: both are one contact.
  cs.clear();
  m.contacts({-0.1, -0.2, -0.1}, 0.5, cs);
  ASSERT_EQ(cs.size(), 1u);
  EXPECT_EQ(cs[0].feature, MeshFeature::vertex);
}

TEST(TriangleMesh, ConcaveCornerOfAnOpenBoxGivesOneContactPerFace) {
  // Floor z = 0 and walls x = 0, y = 0 (two unit squares each): the corner of a box.
  std::vector<Vec3> v;
  std::vector<Tri> t;
  auto square = [&](const Vec3& o, const Vec3& u, const Vec3& w) {
    const auto base = static_cast<std::int32_t>(v.size());
    for (int k = 0; k < 4; ++k) {
      const double a = (k == 1 || k == 2), b = (k >= 2);
      v.push_back({o[0] + a * u[0] + b * w[0], o[1] + a * u[1] + b * w[1], o[2] + a * u[2] + b * w[2]});
    }
    t.push_back({base, base + 1, base + 2}), t.push_back({base, base + 2, base + 3});
  };
  square({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  square({0, 0, 0}, {0, 1, 0}, {0, 0, 1});
  square({0, 0, 0}, {0, 0, 1}, {1, 0, 0});
  // Weld the shared corner and edges the way read_mesh does.
  std::vector<Vec3> uv;
  for (auto& tri : t)
    for (auto& i : tri) {
      const auto x = v[static_cast<std::size_t>(i)];
      auto it = std::find(uv.begin(), uv.end(), x);
      if (it == uv.end()) uv.push_back(x), it = uv.end() - 1;
      i = static_cast<std::int32_t>(it - uv.begin());
    }
  const ContactMesh m(uv, t);
  EXPECT_EQ(m.num_vertices(), 7u);
  std::vector<MeshContact> cs;
  m.contacts({0.3, 0.3, 0.3}, 0.4, cs);  // on every face's diagonal, too
  ASSERT_EQ(cs.size(), 3u);
  expect_near(sum_force(cs), {0.1, 0.1, 0.1}, 1e-15);
  // One per wall, along its normal (face contacts, or the wall's diagonal edge: the centre projects onto
  // each diagonal exactly, so rounding decides which; the contact is the same).
  for (int d = 0; d < 3; ++d) {
    int along = 0;
    for (const auto& c : cs) along += std::abs(c.normal[d] - 1) < 1e-15;
    EXPECT_EQ(along, 1) << "axis " << d;
  }
  cs.clear();
  m.contacts({0.3, 0.6, 0.25}, 0.4, cs);  // floor and the x = 0 wall
  ASSERT_EQ(cs.size(), 2u);
  expect_near(sum_force(cs), {0.1, 0, 0.15}, 1e-15);
  cs.clear();
  m.contacts({0.5, 0.5, 0.3}, 0.4, cs);  // the floor only
  ASSERT_EQ(cs.size(), 1u);
  expect_near(sum_force(cs), {0, 0, 0.1}, 1e-15);
}

TEST(TriangleMesh, OneSidedIgnoresSpheresBehindTheSurface) {
  ContactMesh::Options one;
  one.sides = ContactMesh::Sides::one;
  const auto m1 = cube(one), m2 = cube();
  std::vector<MeshContact> cs;
  m1.contacts({0.5, 0.5, 0.9}, 0.2, cs);  // inside the cube, near the top face
  EXPECT_TRUE(cs.empty());
  m2.contacts({0.5, 0.5, 0.9}, 0.2, cs);
  ASSERT_EQ(cs.size(), 1u);
  expect_near(cs[0].normal, {0, 0, -1}, 0);
  EXPECT_NEAR(cs[0].overlap, 0.1, 1e-15);
}

TEST(TriangleMesh, AMovedMeshGivesTheMovedContacts) {
  const auto rest = cube();
  auto moved = cube();
  RigidTransform pose;
  pose.translation = {2.0, -1.0, 0.5};
  pose.axis_point = {0.5, 0.5, 0.5};
  pose.axis = {1, 2, 3};
  pose.angle = 0.7;
  moved.set_pose(pose);
  // Brought to the world by the pose, directly.
  const double len = std::sqrt(14.0);
  const Vec3 u{1 / len, 2 / len, 3 / len};
  auto world = [&](const Vec3& x, bool point) {
    Vec3 y = x;
    if (point)
      for (int d = 0; d < 3; ++d) y[d] -= pose.axis_point[d];
    const double c = std::cos(pose.angle), s = std::sin(pose.angle);
    const double ud = u[0] * y[0] + u[1] * y[1] + u[2] * y[2];
    const Vec3 uxy{u[1] * y[2] - u[2] * y[1], u[2] * y[0] - u[0] * y[2], u[0] * y[1] - u[1] * y[0]};
    Vec3 z;
    for (int d = 0; d < 3; ++d) z[d] = y[d] * c + uxy[d] * s + u[d] * ud * (1 - c);  // Rodrigues
    if (point)
      for (int d = 0; d < 3; ++d) z[d] += pose.axis_point[d] + pose.translation[d];
    return z;
  };
  for (std::size_t v = 0; v < rest.num_vertices(); ++v)
    expect_near(moved.vertex(v), world(rest.rest_vertex(v), true), 1e-14);
  Uniform rnd(7);
  std::vector<MeshContact> a, b;
  std::size_t seen = 0;
  for (int k = 0; k < 400; ++k) {
    const Vec3 c{1.6 * rnd() - 0.3, 1.6 * rnd() - 0.3, 1.6 * rnd() - 0.3};
    a.clear(), b.clear();
    rest.contacts(c, 0.35, a);
    moved.contacts(world(c, true), 0.35, b);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].feature, b[i].feature);
      EXPECT_EQ(a[i].index, b[i].index);
      expect_near(b[i].point, world(a[i].point, true), 1e-13);
      expect_near(b[i].normal, world(a[i].normal, false), 1e-13);
      EXPECT_NEAR(a[i].overlap, b[i].overlap, 1e-13);
    }
    seen += a.size();
  }
  EXPECT_GT(seen, 100u);
  // Translation only, and back to rest.
  RigidTransform shift;
  shift.translation = {0, 0, 3};
  moved.set_pose(shift);
  a.clear();
  moved.contacts({0.5, 0.5, 4.2}, 0.5, a);
  ASSERT_EQ(a.size(), 1u);
  expect_near(a[0].point, {0.5, 0.5, 4}, 1e-15);
  moved.set_pose({});
  EXPECT_EQ(moved.vertex(7), (Vec3{1, 1, 1}));
  RigidTransform bad;
  bad.axis = {0, 0, 0};
  bad.angle = 1;
  EXPECT_THROW(moved.set_pose(bad), std::invalid_argument);
  EXPECT_EQ(moved.vertex(7), (Vec3{1, 1, 1}));  // unchanged by the refused pose
}

TEST(TriangleMesh, GridCandidatesEqualBruteForceOnALargeBumpyMesh) {
  // A 60 x 60 height field (7,200 triangles) with seeded random heights: bumps, convex and concave edges.
  Uniform rnd(2024);
  const int n = 60;
  std::vector<double> z((n + 1) * (n + 1));
  for (auto& h : z) h = 0.6 * rnd();
  const auto m = flat_grid(n, n, [&](const Vec3& x) {
    return Vec3{x[0] * 0.5, x[1] * 0.5, z[static_cast<std::size_t>(x[1] * (n + 1) + x[0])]};
  });
  EXPECT_EQ(m.num_triangles(), 2u * n * n);
  std::vector<MeshContact> a, b;
  std::vector<std::int32_t> cand;
  std::size_t total = 0, multi = 0;
  for (int k = 0; k < 4000; ++k) {
    const Vec3 c{32 * rnd() - 1, 32 * rnd() - 1, 1.4 * rnd() - 0.4};
    const double r = 0.05 + 0.7 * rnd();
    a.clear(), b.clear();
    m.contacts(c, r, a);
    m.contacts_brute_force(c, r, b);
    ASSERT_EQ(a.size(), b.size()) << "sphere " << k;
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].feature, b[i].feature);
      EXPECT_EQ(a[i].index, b[i].index);
      EXPECT_EQ(a[i].point, b[i].point);
      EXPECT_EQ(a[i].overlap, b[i].overlap);
    }
    total += a.size();
    multi += a.size() > 1;
    // Every triangle the sphere reaches is a candidate (checked on every 40th sphere: it is slow).
    if (k % 40 != 0) continue;
    m.candidates(c, r, cand);
    for (std::size_t t = 0; t < m.num_triangles(); ++t) {
      std::vector<MeshContact> one;
      const auto& tri = m.triangle(t);
      const ContactMesh single({m.rest_vertex(tri[0]), m.rest_vertex(tri[1]), m.rest_vertex(tri[2])},
                               {{0, 1, 2}});
      if (single.contacts(c, r, one) > 0) {
        EXPECT_TRUE(std::binary_search(cand.begin(), cand.end(), static_cast<std::int32_t>(t)));
      }
    }
  }
  EXPECT_GT(total, 1000u);
  EXPECT_GT(multi, 50u);
}

TEST(TriangleMesh, TheSiloHoldsASphereOnItsFloorAndInItsCorner) {
  const auto mesh = basalt::io::read_mesh(basalt::test::source_dir() / "scenes" / "meshes" / "silo.stl");
  const ContactMesh m(mesh.vertices, mesh.triangles);
  EXPECT_EQ(m.boundary_edges(), 2u * 64);  // the top rim and the orifice
  EXPECT_EQ(m.nonmanifold_edges(), 0u);
  std::vector<MeshContact> cs;
  m.contacts({10, 3, 0.8}, 1, cs);  // on the floor
  ASSERT_EQ(cs.size(), 1u);
  expect_near(sum_force(cs), {0, 0, 0.2}, 1e-12);
  cs.clear();
  m.contacts({0, 0, 0.5}, 1, cs);  // over the orifice (radius 4): nothing
  EXPECT_TRUE(cs.empty());
  cs.clear();
  m.contacts({4.5, 0.3, 0.4}, 1, cs);  // on the orifice's rim, centre outside the hole: the floor
  ASSERT_EQ(cs.size(), 1u);
  cs.clear();
  m.contacts({3.8, 0.1, 0.5}, 1, cs);  // over the hole, touching the rim's edge
  ASSERT_EQ(cs.size(), 1u);
  EXPECT_EQ(cs[0].feature, MeshFeature::edge);
  cs.clear();
  m.contacts({-19.3, 0.2, 0.6}, 1, cs);  // in the corner of floor and wall: two contacts
  ASSERT_EQ(cs.size(), 2u);
  EXPECT_GT(sum_force(cs)[0], 0);
  EXPECT_GT(sum_force(cs)[2], 0);
}
