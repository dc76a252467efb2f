// Packing invariants for every volume type, the power-law mode, determinism, bonds, tags, bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "basalt/io/geometry.hpp"
#include "basalt/packer/assembly.hpp"
#include "basalt/packer/error.hpp"
#include "basalt/packer/pack.hpp"
#include "packing_checks.hpp"
#include "test_support.hpp"

using namespace basalt::packer;
namespace fs = std::filesystem;
namespace chk = basalt::packer::test;

namespace {

PackOptions options(double rmin, double rmax, std::uint64_t seed = 3) {
  return chk::options(rmin, rmax, seed);
}
using chk::expect_valid;

std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

}  // namespace

TEST(Pack, BoxIsFilledDenselyWithoutOverlapsAndInside) {
  auto box = make_box({0, 0, 0}, {6, 6, 6});
  const auto o = options(0.2, 1.0);
  const auto p = pack(*box, o);
  expect_valid(*box, p, o);
  // 0.70 on a 15 mm cube (GenGeo 0.685); a 6 mm box is a third wall layer (~0.5 dense), still dense.
  EXPECT_GT(chk::solid_fraction(*box, p), 0.6);
  // Spheres touch the walls: the void filler fits them tangent to the boundary planes.
  int touching_floor = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (std::abs(p.centre[i][2] - p.radius[i]) < 1e-9) ++touching_floor;
  EXPECT_GT(touching_floor, 10);
}

TEST(Pack, BoxAwayFromTheOriginAndFlat) {
  auto box = make_box({-3, 10, 100}, {5, 14, 103.5});
  const auto o = options(0.25, 0.8, 11);
  const auto p = pack(*box, o);
  expect_valid(*box, p, o);
  EXPECT_GT(chk::solid_fraction(*box, p), 0.5);  // mostly wall layer
}

TEST(Pack, CylinderAndSphereVolumes) {
  auto cyl = make_cylinder({1, 2, 3}, 3.0, 5.0);
  auto ball = make_sphere({-1, 0, 2}, 3.5);
  for (const Volume* v : {cyl.get(), ball.get()}) {
    const auto o = options(0.2, 0.9, 5);
    const auto p = pack(*v, o);
    expect_valid(*v, p, o);
    EXPECT_GT(chk::solid_fraction(*v, p), 0.6) << v->description();
    // Curved walls are touched too (tangent planes relinearised until they settle).
    int touching = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (std::abs(v->signed_distance(p.centre[i]) - p.radius[i]) < 1e-6) ++touching;
    EXPECT_GT(touching, 20) << v->description();
  }
}

TEST(Pack, ClosedTriangleMeshVolume) {
  const auto dir = basalt::test::scratch_dir("packer-mesh");
  chk::write_text(dir / "cube.off", chk::cube_off(5.0));
  auto mesh = load_mesh(dir / "cube.off");
  EXPECT_NEAR(mesh->measure(), 125.0, 1e-9);
  EXPECT_NEAR(mesh->signed_distance({2.5, 2.5, 1.0}), 1.0, 1e-12);
  EXPECT_LT(mesh->signed_distance({2.5, 2.5, -1.0}), 0);
  const auto o = options(0.2, 0.8, 9);
  const auto p = pack(*mesh, o);
  expect_valid(*mesh, p, o);
  // Same region as an analytic box: inside it too.
  auto box = make_box({0, 0, 0}, {5, 5, 5});
  EXPECT_LE(chk::worst_protrusion(*box, p), 1e-6);
  EXPECT_GT(chk::solid_fraction(*mesh, p), 0.6);
  // Mesh faces are flat pieces: spheres touch them exactly, as they touch a box's walls.
  int touching_floor = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (std::abs(p.centre[i][2] - p.radius[i]) < 1e-9) ++touching_floor;
  EXPECT_GT(touching_floor, 5);
}

TEST(Pack, NonConvexMeshVolume) {
  // An L-shaped prism: the union of [0,4]x[0,2] and [0,2]x[0,4], 3 high (polygon faces, triangulated by
  // CGAL).
  const auto dir = basalt::test::scratch_dir("packer-lmesh");
  chk::write_text(
      dir / "L.off",
      "OFF\n12 8 0\n0 0 0\n4 0 0\n4 2 0\n2 2 0\n2 4 0\n0 4 0\n0 0 3\n4 0 3\n4 2 3\n2 2 3\n"
      "2 4 3\n0 4 3\n6 5 4 3 2 1 0\n6 6 7 8 9 10 11\n4 0 1 7 6\n4 1 2 8 7\n4 2 3 9 8\n4 3 4 10 9\n"
      "4 4 5 11 10\n4 5 0 6 11\n");
  auto mesh = load_mesh(dir / "L.off");
  EXPECT_NEAR(mesh->measure(), 36.0, 1e-9);
  const auto o = options(0.15, 0.6, 12);
  const auto p = pack(*mesh, o);
  expect_valid(*mesh, p, o);
  // Inside the L by an analytic test, independent of CGAL.
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto& c = p.centre[i];
    const double r = p.radius[i] - 1e-6;
    const bool arm1 = c[0] >= r && c[0] <= 4 - r && c[1] >= r && c[1] <= 2 - r;
    const bool arm2 = c[0] >= r && c[0] <= 2 - r && c[1] >= r && c[1] <= 4 - r;
    const bool corner = c[0] >= r && c[1] >= r && c[0] <= 4 - r && c[1] <= 4 - r &&
                        (c[0] <= 2 || c[1] <= 2) &&
                        (c[0] <= 2 - r || c[1] <= 2 - r || std::hypot(c[0] - 2, c[1] - 2) >= r);
    EXPECT_TRUE((arm1 || arm2 || corner) && c[2] >= r && c[2] <= 3 - r) << "sphere " << i << " pokes out";
  }
  EXPECT_GT(chk::solid_fraction(*mesh, p), 0.5);  // 3 high with rmax 0.6: mostly wall layer
}

TEST(Pack, BadMeshesAreRefusedWithTheReason) {
  const auto dir = basalt::test::scratch_dir("packer-badmesh");
  chk::write_text(dir / "open.off", chk::cube_off(5.0, 2));
  try {
    load_mesh(dir / "open.off");
    ADD_FAILURE() << "an open mesh was accepted";
  } catch (const PackError& e) {
    EXPECT_NE(std::string(e.what()).find("open"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("open.off"), std::string::npos) << e.what();
  }
  // Two closed tetrahedra that pass through each other.
  chk::write_text(dir / "crossing.off",
                  "OFF\n8 8 0\n0 0 0\n4 0 0\n0 4 0\n0 0 4\n1 1 1\n5 1 1\n1 5 1\n1 1 5\n"
                  "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n3 4 6 5\n3 4 5 7\n3 4 7 6\n3 5 6 7\n");
  try {
    load_mesh(dir / "crossing.off");
    ADD_FAILURE() << "a self-intersecting mesh was accepted";
  } catch (const PackError& e) {
    EXPECT_NE(std::string(e.what()).find("intersects itself"), std::string::npos) << e.what();
  }
  EXPECT_THROW(load_mesh(dir / "missing.off"), PackError);
  chk::write_text(dir / "garbage.off", "OFF\nthis is not a mesh\n");
  EXPECT_THROW(load_mesh(dir / "garbage.off"), PackError);
  chk::write_text(dir / "cube.xyz", chk::cube_off(5.0));
  EXPECT_THROW(load_mesh(dir / "cube.xyz"), PackError);
}

TEST(Pack, SameSeedSameSpheresOtherSeedOthers) {
  auto box = make_box({0, 0, 0}, {5, 5, 5});
  const auto a = pack(*box, options(0.2, 1.0, 42));
  const auto b = pack(*box, options(0.2, 1.0, 42));
  const auto c = pack(*box, options(0.2, 1.0, 43));
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.centre, b.centre);
  EXPECT_EQ(a.radius, b.radius);
  EXPECT_NE(a.centre, c.centre);
}

TEST(Pack, SameSeedSameFileByteForByte) {
  const auto dir = basalt::test::scratch_dir("packer-bytes");
  auto box = make_box({0, 0, 0}, {5, 5, 5});
  const auto o = options(0.2, 1.0, 7);
  AssemblyOptions ao;
  std::string files[2];
  for (int run = 0; run < 2; ++run) {
    AssemblyStats st;
    ao.threads = run + 1;  // the thread count does not change the result either
    const auto g = assemble(*box, pack(*box, o), o, ao, st);
    const auto f = dir / ("run" + std::to_string(run) + ".geo");
    basalt::io::write_geometry(g, f);
    files[run] = slurp(f);
  }
  EXPECT_GT(files[0].size(), 1000u);
  EXPECT_TRUE(files[0] == files[1]) << "same seed, different bytes";
}

TEST(Pack, BondsJoinExactlyThePairsWithinTheTolerance) {
  auto box = make_box({0, 0, 0}, {5, 5, 5});
  const auto o = options(0.2, 1.0, 8);
  auto p = pack(*box, o);
  // Make the rule bite: move some spheres apart by gaps just inside and just outside the tolerance.
  const double tol = 1e-5;
  for (std::size_t i = 0; i < p.size(); i += 7) p.radius[i] *= (1 - (i % 2 ? 0.5 : 2.0) * tol / p.radius[i]);
  AssemblyOptions ao;
  ao.bond_tolerance = tol;
  AssemblyStats st;
  const auto g = assemble(*box, p, o, ao, st);
  std::set<std::pair<std::int64_t, std::int64_t>> bonds;
  for (const auto& b : g.bonds) bonds.emplace(std::min(b.a, b.b), std::max(b.a, b.b));
  const auto expected = chk::pairs_within(p, tol);
  EXPECT_EQ(bonds, expected);
  EXPECT_EQ(bonds.size(), g.bonds.size());  // no duplicates
  EXPECT_GT(expected.size(), p.size());     // a bonded solid, not a few contacts
  EXPECT_NEAR(st.mean_coordination, 2.0 * expected.size() / p.size(), 1e-12);
  EXPECT_NEAR(st.bonds_per_particle, 1.0 * expected.size() / p.size(), 1e-12);
  // With the tolerance at zero, the shrunk spheres lose their bonds.
  ao.bond_tolerance = 0;
  const auto g0 = assemble(*box, p, o, ao, st);
  EXPECT_LT(g0.bonds.size(), g.bonds.size());
  EXPECT_EQ(g0.bonds.size(), chk::pairs_within(p, 0).size());
}

TEST(Pack, StatisticsAreStoredWithTheGeometry) {
  auto box = make_box({0, 0, 0}, {5, 5, 5});
  const auto o = options(0.2, 1.0, 8);
  const auto p = pack(*box, o);
  AssemblyOptions ao;
  AssemblyStats st;
  const auto g = assemble(*box, p, o, ao, st);
  EXPECT_EQ(g.size(), p.size());
  EXPECT_EQ(g.statistics.at("particle_count").at(0), static_cast<double>(p.size()));
  EXPECT_NEAR(g.statistics.at("solid_fraction").at(0), chk::solid_fraction(*box, p), 1e-12);
  double total = 0;
  for (double c : g.statistics.at("radius_histogram_counts")) total += c;
  EXPECT_EQ(total, static_cast<double>(p.size()));
  EXPECT_EQ(g.statistics.at("radius_histogram_edges").size(),
            g.statistics.at("radius_histogram_counts").size() + 1);
  EXPECT_LE(g.statistics.at("largest_overlap").at(0), o.overlap_tolerance);
  EXPECT_EQ(g.attributes.at("seed"), "8");
  EXPECT_EQ(g.statistics.count("pack_seconds"), 0u);  // no wall-clock time unless asked (byte identity)
}

TEST(Pack, PowerLawIsFollowedOverADecadeOfRadius) {
  for (double alpha : {1.5, 2.0, 2.6}) {
    auto box = make_box({0, 0, 0}, {5, 5, 5});
    auto o = options(0.1, 1.0, 21);
    o.exponent = alpha;
    o.target_fraction = 0.5;
    const auto p = pack(*box, o);
    expect_valid(*box, p, o);
    const auto h = radius_histogram(p.radius, o.rmin, o.rmax, 16);
    EXPECT_NEAR(h.exponent, alpha, 0.1) << "alpha " << alpha << ", " << p.size() << " spheres";
    EXPECT_EQ(p.not_placed, 0u) << "alpha " << alpha;
    EXPECT_NEAR(chk::solid_fraction(*box, p), 0.5, 0.03);
  }
}

TEST(Pack, PowerLawRadiiAndTheFittedExponent) {
  const auto radii = power_law_radii(0.1, 1.0, 2.0, 500.0, 1);
  ASSERT_GT(radii.size(), 1000u);
  EXPECT_TRUE(std::is_sorted(radii.rbegin(), radii.rend()));
  EXPECT_GE(radii.back(), 0.1);
  EXPECT_LE(radii.front(), 1.0);
  double solid = 0;
  for (double r : radii) solid += 4.0 / 3.0 * M_PI * r * r * r;
  EXPECT_NEAR(solid, 500.0, 0.02 * 500);
  EXPECT_NEAR(radius_histogram(radii, 0.1, 1.0, 20).exponent, 2.0, 0.03);
  // Exact power-law counts give the exponent back exactly.
  std::vector<double> synthetic;
  for (int k = 0; k < 10; ++k) {
    const double r = 0.1 * std::pow(10.0, (k + 0.5) / 10);
    for (int c = 0; c < static_cast<int>(std::lround(1000 * std::pow(r / 0.1, -1.5))); ++c)
      synthetic.push_back(r);
  }
  EXPECT_NEAR(radius_histogram(synthetic, 0.1, 1.0, 10).exponent, 1.5, 0.01);
}

TEST(Pack, DenseModeReportsTheExponentThatEmerges) {
  auto box = make_box({0, 0, 0}, {6, 6, 6});
  const auto o = options(0.2, 1.0, 2);
  const auto p = pack(*box, o);
  AssemblyStats st;
  assemble(*box, p, o, AssemblyOptions{}, st);
  EXPECT_TRUE(std::isfinite(st.histogram.exponent));
  EXPECT_GT(st.histogram.exponent, 0.5);  // more small spheres than big ones
}

TEST(Pack, RegionTagsMarkLayersNextToFaces) {
  auto box = make_box({0, 0, 0}, {5, 5, 5});
  const auto o = options(0.2, 1.0, 4);
  const auto p = pack(*box, o);
  const auto tags =
      region_tags(*box, p.centre, p.radius, {parse_tag_layer("zmin:0.5:2"), parse_tag_layer("xmax:0:7")});
  int twos = 0, sevens = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const bool near_xmax = 5 - p.centre[i][0] - p.radius[i] <= 0;
    const bool near_zmin = p.centre[i][2] - p.radius[i] <= 0.5;
    EXPECT_EQ(tags[i], near_xmax ? 7 : near_zmin ? 2 : 0) << "particle " << i;
    twos += tags[i] == 2;
    sevens += tags[i] == 7;
  }
  EXPECT_GT(twos, 5);
  EXPECT_GT(sevens, 5);  // spheres touching the wall within tolerance count as touching
  auto ball = make_sphere({0, 0, 0}, 3);
  const auto q = pack(*ball, o);
  const auto surf = region_tags(*ball, q.centre, q.radius, {parse_tag_layer("surface:0.3:1")});
  for (std::size_t i = 0; i < q.size(); ++i)
    EXPECT_EQ(surf[i], 3 - norm(q.centre[i]) - q.radius[i] <= 0.3 ? 1 : 0);
  EXPECT_THROW(region_tags(*box, p.centre, p.radius, {parse_tag_layer("side:1:1")}), PackError);
  EXPECT_THROW(parse_tag_layer("zmin:0.5"), PackError);
  EXPECT_THROW(parse_tag_layer("zmin:x:2"), PackError);
  EXPECT_THROW(parse_tag_layer("zmin:0.5:two"), PackError);
}

TEST(Pack, ImpossibleRequestsAreRefused) {
  auto box = make_box({0, 0, 0}, {5, 5, 5});
  auto expect_error = [&](const Volume& v, PackOptions o, const char* words) {
    try {
      pack(v, o);
      ADD_FAILURE() << "accepted: " << words;
    } catch (const PackError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  expect_error(*box, options(1.0, 0.5), "rmin must not exceed rmax");
  expect_error(*box, options(0.0, 0.5), "rmin must be > 0");
  expect_error(*box, options(-0.1, 0.5), "rmin must be > 0");
  expect_error(*make_box({0, 0, 0}, {0.3, 5, 5}), options(0.2, 0.5), "too small for one sphere");
  // Wide enough in every direction, but the corner tetrahedron's inscribed ball has radius 0.845 < 0.9.
  const auto dir = basalt::test::scratch_dir("packer-small");
  chk::write_text(dir / "tet.off",
                  "OFF\n4 4 0\n0 0 0\n4 0 0\n0 4 0\n0 0 4\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  expect_error(*load_mesh(dir / "tet.off"), options(0.9, 1.0), "too small for one sphere");
  auto few = options(0.2, 1.0);
  few.seed_fraction = 0.0;
  expect_error(*box, few, "seed fraction must be in");
  auto pl = options(0.2, 1.0);
  pl.exponent = -1;
  expect_error(*box, pl, "exponent must be > 0");
  EXPECT_THROW(make_box({0, 0, 0}, {1, -1, 1}), PackError);
  EXPECT_THROW(make_cylinder({0, 0, 0}, 0, 1), PackError);
  EXPECT_THROW(make_sphere({0, 0, 0}, -2), PackError);
}

TEST(Pack, ASmallVolumeHoldsAtLeastOneSphere) {
  auto box = make_box({0, 0, 0}, {0.5, 0.5, 0.5});
  const auto o = options(0.2, 1.0);
  const auto p = pack(*box, o);
  expect_valid(*box, p, o);
}

TEST(Pack, ProgressIsReportedAndEndsAtOne) {
  auto box = make_box({0, 0, 0}, {15, 15, 15});  // ~5,000 spheres: progress every 4,096 placements
  auto o = options(0.2, 1.0, 6);
  std::vector<double> seen;
  o.progress = [&](double f) { seen.push_back(f); };
  const auto p = pack(*box, o);
  ASSERT_GE(seen.size(), 2u) << p.size() << " spheres";
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_GT(seen.front(), 0.0);
  EXPECT_LT(seen[seen.size() - 2], 1.0);
  EXPECT_EQ(seen.back(), 1.0);
}

TEST(Pack, LatticeWithJitterIsLooseDeterministicAndValid) {
  // The granular fill: one sphere per lattice cell of side 2 rmax that fits, radii across [rmin, rmax],
  // never overlapping nor leaving the volume, the same for the same seed, different for another.
  auto box = make_box({0, 0, 0}, {10, 8, 20});
  auto o = options(0.4, 0.5);
  const auto p = lattice_packing(*box, o);
  expect_valid(*box, p, o);
  EXPECT_EQ(p.size(), 10u * 8u * 20u);
  const double f = chk::solid_fraction(*box, p);
  EXPECT_GT(f, 0.3);
  EXPECT_LT(f, 0.53);  // pi/6 at most (every radius rmax)
  double lo = 1, hi = 0;
  for (double r : p.radius) lo = std::min(lo, r), hi = std::max(hi, r);
  EXPECT_LT(lo, 0.41);
  EXPECT_GT(hi, 0.49);
  const auto again = lattice_packing(*box, o);
  EXPECT_EQ(again.centre, p.centre);
  o.seed = 99;
  EXPECT_NE(lattice_packing(*box, o).centre, p.centre);
  auto cyl = make_cylinder({0, 0, 0}, 3, 6);
  const auto c = lattice_packing(*cyl, options(0.4, 0.5));
  expect_valid(*cyl, c, options(0.4, 0.5));
}
