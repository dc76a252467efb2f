// Apollonius solves: balls tangent to four spheres/planes, and balls of a given radius tangent to three.
#include <gtest/gtest.h>

#include <cmath>

#include "tangent.hpp"

using namespace basalt::packer;
using namespace basalt::packer::detail;

namespace {

Object sphere(Vec3 c, double r) {
  Object o;
  o.c = c;
  o.r = r;
  return o;
}
Object plane(Vec3 n, double d) {
  Object o;
  o.is_plane = true;
  o.plane.n = n;
  o.plane.d = d;
  return o;
}

}  // namespace

TEST(Tangent, BallInTheHoleOfFourEqualTouchingSpheres) {
  // Unit spheres at the vertices of a regular tetrahedron of edge 2 touch each other; the hole between them
  // holds a ball of radius sqrt(3/2) - 1 at the centroid.
  const double s = std::sqrt(2.0);
  std::array<Object, 4> o = {sphere({1, 0, -1 / s}, 1), sphere({-1, 0, -1 / s}, 1), sphere({0, 1, 1 / s}, 1),
                             sphere({0, -1, 1 / s}, 1)};
  auto ball = tangent_ball(o, {0, 0, 0});
  ASSERT_TRUE(ball);
  EXPECT_NEAR(ball->r, std::sqrt(1.5) - 1, 1e-12);
  EXPECT_NEAR(norm(ball->c), 0, 1e-12);
  for (const auto& x : o) EXPECT_NEAR(gap(*ball, x), 0, 1e-12);
}

TEST(Tangent, UnequalSpheresAndAPlaneAreAllTouched) {
  std::array<Object, 4> o = {sphere({0, 0, 1}, 1), sphere({2.5, 0, 0.7}, 0.7), sphere({1, 2.2, 0.5}, 0.5),
                             plane({0, 0, 1}, 0)};
  auto ball = tangent_ball(o, {1.2, 0.8, 0.3});
  ASSERT_TRUE(ball);
  EXPECT_GT(ball->r, 0);
  for (const auto& x : o) EXPECT_NEAR(gap(*ball, x), 0, 1e-10);
  // Touching the plane from its inner side: centre at height r.
  EXPECT_NEAR(ball->c[2], ball->r, 1e-10);
}

TEST(Tangent, CornerOfThreePlanesAndASphere) {
  std::array<Object, 4> o = {plane({1, 0, 0}, 0), plane({0, 1, 0}, 0), plane({0, 0, 1}, 0),
                             sphere({2, 2, 2}, 1)};
  auto ball = tangent_ball(o, {0.3, 0.3, 0.3});
  ASSERT_TRUE(ball);
  // Centre (r, r, r) with |(2,2,2) - (r,r,r)| = sqrt(3) (2 - r) = 1 + r.
  const double r = (2 * std::sqrt(3.0) - 1) / (std::sqrt(3.0) + 1);
  EXPECT_NEAR(ball->r, r, 1e-12);
  for (const auto& x : o) EXPECT_NEAR(gap(*ball, x), 0, 1e-12);
}

TEST(Tangent, NoSolutionWithoutASphereOrForDegenerateInput) {
  std::array<Object, 4> planes = {plane({1, 0, 0}, 0), plane({0, 1, 0}, 0), plane({0, 0, 1}, 0),
                                  plane({-1, 0, 0}, -5)};
  EXPECT_FALSE(tangent_ball(planes, {1, 1, 1}));
  // Four collinear centres: the linear system is singular.
  std::array<Object, 4> line = {sphere({0, 0, 0}, 1), sphere({3, 0, 0}, 1), sphere({6, 0, 0}, 1),
                                sphere({9, 0, 0}, 1)};
  EXPECT_FALSE(tangent_ball(line, {1, 1, 1}));
}

TEST(Tangent, GivenRadiusTouchesThreeObjects) {
  const Object a = sphere({0, 0, 0}, 1), b = sphere({3, 0, 0}, 1.2), c = plane({0, 0, 1}, -1);
  Ball out[2];
  const int n = tangent_balls(a, b, c, 0.6, out);
  ASSERT_EQ(n, 2);
  for (int i = 0; i < n; ++i) {
    EXPECT_DOUBLE_EQ(out[i].r, 0.6);
    EXPECT_NEAR(gap(out[i], a), 0, 1e-12);
    EXPECT_NEAR(gap(out[i], b), 0, 1e-12);
    EXPECT_NEAR(gap(out[i], c), 0, 1e-12);
  }
  EXPECT_GT(norm(out[0].c - out[1].c), 0.1);  // mirror images about the line through the centres
  // Too far apart for a small ball to touch both.
  EXPECT_EQ(tangent_balls(sphere({0, 0, 0}, 1), sphere({10, 0, 0}, 1), plane({0, 0, 1}, -1), 0.5, out), 0);
}

TEST(Tangent, ThreePlanesGiveOneCornerBall) {
  Ball out[2];
  ASSERT_EQ(tangent_balls(plane({1, 0, 0}, 0), plane({0, 1, 0}, 0), plane({0, 0, -1}, -4), 0.5, out), 1);
  EXPECT_NEAR(out[0].c[0], 0.5, 1e-15);
  EXPECT_NEAR(out[0].c[1], 0.5, 1e-15);
  EXPECT_NEAR(out[0].c[2], 3.5, 1e-15);
}
