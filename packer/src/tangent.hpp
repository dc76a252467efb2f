#pragma once
// Spheres tangent to spheres and planes (Apollonius' problem in 3-D). Pure functions.
#include <array>
#include <optional>

#include "basalt/packer/vec3.hpp"
#include "basalt/packer/volume.hpp"

namespace basalt::packer::detail {

/// A sphere (centre, radius) or a plane (a ball "tangent" to it lies on its inner side, touching it).
struct Object {
  bool is_plane = false;
  Vec3 c{0, 0, 0};
  double r = 0;
  Plane plane;
};

struct Ball {
  Vec3 c{0, 0, 0};
  double r = 0;
};

/// The ball touching all four objects (externally for spheres, on the inner side of planes) with a
/// positive radius; of two such balls, the one whose centre is nearer `near`. Needs at least one sphere.
std::optional<Ball> tangent_ball(const std::array<Object, 4>& o, const Vec3& near);

/// Balls of radius rho touching the three objects; writes up to two and returns how many.
int tangent_balls(const Object& a, const Object& b, const Object& c, double rho, Ball out[2]);

/// Gap between a ball and an object (negative when they overlap).
inline double gap(const Ball& ball, const Object& o) {
  return o.is_plane ? o.plane.distance(ball.c) - ball.r : norm(ball.c - o.c) - ball.r - o.r;
}

}  // namespace basalt::packer::detail
