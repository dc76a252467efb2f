#include "tangent.hpp"

#include <cmath>

namespace basalt::packer::detail {

namespace {

/// Solves the 3x3 system rows[i] . x = rhs[i] (Cramer); false when (nearly) singular.
bool solve3(const Vec3 rows[3], const Vec3& rhs, Vec3& x) {
  const Vec3 c12 = cross(rows[1], rows[2]);
  const double det = dot(rows[0], c12);
  const double scale = norm(rows[0]) * norm(rows[1]) * norm(rows[2]);
  if (!(std::abs(det) > 1e-12 * scale)) return false;
  const Vec3 c20 = cross(rows[2], rows[0]);
  const Vec3 c01 = cross(rows[0], rows[1]);
  // Inverse columns are c12, c20, c01 over det.
  x = (1.0 / det) * (rhs[0] * c12 + rhs[1] * c20 + rhs[2] * c01);
  return true;
}

/// Real roots of a t^2 + 2 h t + k = 0 (numerically stable); returns their number.
int quadratic(double a, double h, double k, double t[2]) {
  const double scale = std::abs(a) + std::abs(h) + 1e-300;
  if (std::abs(a) < 1e-14 * scale) {
    if (h == 0) return 0;
    t[0] = -k / (2 * h);
    return 1;
  }
  double disc = h * h - a * k;
  if (disc < 0) {
    if (disc > -1e-14 * (h * h + std::abs(a * k)))
      disc = 0;
    else
      return 0;
  }
  const double s = std::sqrt(disc);
  const double q = -(h + std::copysign(s, h));  // q = -(h + sign(h) s)
  if (q == 0) {
    t[0] = 0;
    return 1;
  }
  t[0] = q / a;
  t[1] = k / q;
  return 2;
}

}  // namespace

std::optional<Ball> tangent_ball(const std::array<Object, 4>& o, const Vec3& near) {
  int ref = -1;
  for (int i = 0; i < 4; ++i)
    if (!o[i].is_plane) {
      ref = i;
      break;
    }
  if (ref < 0) return std::nullopt;
  const Vec3& c0 = o[ref].c;
  const double r0 = o[ref].r;
  // Rows a . c + e r = b, expressed relative to c0 for conditioning.
  Vec3 rows[3];
  Vec3 b{}, e{};
  int k = 0;
  for (int i = 0; i < 4; ++i) {
    if (i == ref) continue;
    if (o[i].is_plane) {
      rows[k] = o[i].plane.n;
      e[k] = -1;
      b[k] = -o[i].plane.distance(c0);  // n . (c - c0) - r = d - n . c0
    } else {
      const Vec3 dc = o[i].c - c0;
      rows[k] = dc;
      e[k] = o[i].r - r0;
      // |c - ci|^2 = (r + ri)^2 minus |c - c0|^2 = (r + r0)^2, with y = c - c0:
      // -2 dc . y + |dc|^2 = 2 r (ri - r0) + ri^2 - r0^2
      b[k] = 0.5 * (norm2(dc) - o[i].r * o[i].r + r0 * r0);
    }
    ++k;
  }
  Vec3 u, v;  // y = u + v r
  if (!solve3(rows, b, u) || !solve3(rows, -1.0 * e, v)) return std::nullopt;
  // |y|^2 = (r + r0)^2
  double t[2];
  const int n = quadratic(dot(v, v) - 1, dot(u, v) - r0, dot(u, u) - r0 * r0, t);
  std::optional<Ball> best;
  double best_d = 0;
  for (int i = 0; i < n; ++i) {
    if (!(t[i] > 0) || !std::isfinite(t[i])) continue;
    Ball ball{c0 + u + t[i] * v, t[i]};
    const double d = norm2(ball.c - near);
    if (!best || d < best_d) {
      best = ball;
      best_d = d;
    }
  }
  return best;
}

int tangent_balls(const Object& a, const Object& b, const Object& c, double rho, Ball out[2]) {
  const Object* o[3] = {&a, &b, &c};
  int ref = -1;
  for (int i = 0; i < 3; ++i)
    if (!o[i]->is_plane) {
      ref = i;
      break;
    }
  if (ref < 0) {  // three planes: one point at distance rho from each
    Vec3 rows[3], rhs;
    for (int i = 0; i < 3; ++i) {
      rows[i] = o[i]->plane.n;
      rhs[i] = o[i]->plane.d + rho;
    }
    Vec3 x;
    if (!solve3(rows, rhs, x)) return 0;
    out[0] = {x, rho};
    return 1;
  }
  const Vec3& c0 = o[ref]->c;
  const double r0 = o[ref]->r;
  Vec3 rows[2];
  double rhs[2];
  int k = 0;
  for (int i = 0; i < 3; ++i) {
    if (i == ref) continue;
    if (o[i]->is_plane) {
      rows[k] = o[i]->plane.n;
      rhs[k] = rho - o[i]->plane.distance(c0);  // n . y = d + rho - n . c0
    } else {
      const Vec3 dc = o[i]->c - c0;
      rows[k] = dc;
      const double ri = o[i]->r;
      rhs[k] = 0.5 * (norm2(dc) - (rho + ri) * (rho + ri) + (rho + r0) * (rho + r0));
    }
    ++k;
  }
  const Vec3 w = cross(rows[0], rows[1]);
  const double w2 = norm2(w);
  if (!(w2 > 1e-24 * norm2(rows[0]) * norm2(rows[1]))) return 0;
  const Vec3 p = (1.0 / w2) * (rhs[0] * cross(rows[1], w) + rhs[1] * cross(w, rows[0]));
  const Vec3 wh = (1.0 / std::sqrt(w2)) * w;
  // |p + t wh|^2 = (rho + r0)^2
  const double h = dot(p, wh);
  const double disc = h * h - (norm2(p) - (rho + r0) * (rho + r0));
  if (disc < 0) return 0;
  const double s = std::sqrt(disc);
  out[0] = {c0 + p + (-h - s) * wh, rho};
  if (s == 0) return 1;
  out[1] = {c0 + p + (-h + s) * wh, rho};
  return 2;
}

}  // namespace basalt::packer::detail
