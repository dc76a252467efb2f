// EsysBoxPacker, EsysStream: the ESyS front end's RandomBoxPacker (python/basalt/esys/packer.py, docs/esys.md
// "RandomBoxPacker"): ESyS-Particle 2.3.5's random packing of a 3-D box without periodic axes, the same
// spheres, ids and order bit for bit. Written from a reading of ESyS's algorithm (Geometry/RandomBoxPacker,
// CubicBoxPacker, BoxPacker, SphereFitter, Sphere3d, NeighbourTable; Foundation/Rng), not from its code; it
// was Python (packer.py) first, and every floating-point operation here is the one that code made, in its
// order. Compiled with -ffp-contract=off (python/CMakeLists.txt): a fused multiply-add would round
// differently.
//
// - one random stream for the whole process (EsysStream, held by packer.py): MT19937 with its default seed
// 5489,
//   each number a 32-bit draw divided by 2^32 (Boost's uniform_real on [0, 1)); a second packer continues it;
// - first a regular close packing on a grid of spacing cubicPackRadius (its points in ESyS's order), each
// sphere of
//   a random radius, kept where it lies inside the box and overlaps no sphere already kept;
// - then random insertion: a random point (z, y, x drawn in that order: ESyS's compiler evaluates its
//   Vec3(random, random, random) right to left) and a random radius; its four closest spheres found through
//   ESyS's cell table (cells 8 minRadius wide; closest = smallest distance minus radius among the spheres of
//   the cells searched, ties to the lower id); the closest of the six walls; three fitters tried in turn
//   (move the sphere onto the surface of its closest neighbour; the sphere touching four neighbours; the
//   sphere touching three neighbours and the wall); the first valid fit is inserted; the packing ends once
//   maxInsertFails candidates in a row found no fit.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "bindings.hpp"

namespace basalt::python {
namespace {

using Vec = std::array<double, 3>;

struct Sphere {
  Vec c;
  double r;
};

/// The process's one random stream (ESyS's static generator).
class EsysStream {
 public:
  double uniform() { return double(mt_()) / 4294967296.0; }

 private:
  std::mt19937 mt_;  // default seed 5489, as ESyS's (and numpy's RandomState(5489))
};

/// The sphere touching four spheres (ESyS's Sphere3D::FillIn).
std::optional<Sphere> fill_in_4(const Vec& p1, const Vec& p2, const Vec& p3, const Vec& p4, double r1,
                                double r2, double r3, double r4) {
  const double x1 = p1[0], y1 = p1[1], z1 = p1[2];
  const double x2 = p2[0], y2 = p2[1], z2 = p2[2];
  const double x3 = p3[0], y3 = p3[1], z3 = p3[2];
  const double x4 = p4[0], y4 = p4[1], z4 = p4[2];
  const double ax = (y2 - y1) * (y4 - y1);
  const double ay = (z2 - z1) * (z4 - z1);
  const double az = (x2 - x1) * (x4 - x1);
  const double bx = (y3 - y1) * (y4 - y1);
  const double by = (z3 - z1) * (z4 - z1);
  const double bz = (x3 - x1) * (x4 - x1);
  const double cx = (y3 - y1) * (y2 - y1);
  const double cy = (z3 - z1) * (z2 - z1);
  const double cz = (x3 - x1) * (x2 - x1);
  const double Ax = (x3 - x1) * ax - (x2 - x1) * bx;
  const double Ay = (y3 - y1) * ay - (y2 - y1) * by;
  const double Az = (z3 - z1) * az - (z2 - z1) * bz;
  const double Bx = (z4 - z1) * cx - (z2 - z1) * bx;
  const double By = (x4 - x1) * cy - (x2 - x1) * by;
  const double Bz = (y4 - y1) * cz - (y2 - y1) * bz;
  const double Cx = (x4 - x1) * cx - (x2 - x1) * bx;
  const double Cy = (y4 - y1) * cy - (y2 - y1) * by;
  const double Cz = (z4 - z1) * cz - (z2 - z1) * bz;
  const double Dx = (z3 - z1) * ax - (z2 - z1) * bx;
  const double Dy = (x3 - x1) * ay - (x2 - x1) * by;
  const double Dz = (y3 - y1) * az - (y2 - y1) * bz;
  const double Ex = Ax * Bx - Cx * Dx;
  const double Ey = Ay * By - Cy * Dy;
  const double Ez = Az * Bz - Cz * Dz;
  if (Ex == 0.0 || Ey == 0.0 || Ez == 0.0) return std::nullopt;
  const double a12 = r1 - r2;
  const double b12 = r1 * r1 - r2 * r2 - (x1 * x1 + y1 * y1 + z1 * z1) + (x2 * x2 + y2 * y2 + z2 * z2);
  const double a13 = r1 - r3;
  const double b13 = r1 * r1 - r3 * r3 - (x1 * x1 + y1 * y1 + z1 * z1) + (x3 * x3 + y3 * y3 + z3 * z3);
  const double a14 = r1 - r4;
  const double b14 = r1 * r1 - r4 * r4 - (x1 * x1 + y1 * y1 + z1 * z1) + (x4 * x4 + y4 * y4 + z4 * z4);
  const double alx = (Bx * a13 * ax - Bx * a12 * bx - Dx * a14 * cx + Dx * a12 * bx) / Ex;
  const double aly = (By * a13 * ay - By * a12 * by - Dy * a14 * cy + Dy * a12 * by) / Ey;
  const double alz = (Bz * a13 * az - Bz * a12 * bz - Dz * a14 * cz + Dz * a12 * bz) / Ez;
  const double bex = (Bx * b13 * ax - Bx * b12 * bx - Dx * b14 * cx + Dx * b12 * bx) / (2.0 * Ex);
  const double bey = (By * b13 * ay - By * b12 * by - Dy * b14 * cy + Dy * b12 * by) / (2.0 * Ey);
  const double bez = (Bz * b13 * az - Bz * b12 * bz - Dz * b14 * cz + Dz * b12 * bz) / (2.0 * Ez);
  const double aa = (alx * alx + aly * aly + alz * alz) - 1.0;
  const double bb =
      2.0 * (alx * bex + aly * bey + alz * bez) - 2.0 * (alx * x4 + aly * y4 + alz * z4) - 2.0 * r4;
  const double cc = ((bex * bex + bey * bey + bez * bez) + (x4 * x4 + y4 * y4 + z4 * z4) -
                     2.0 * (bex * x4 + bey * y4 + bez * z4) - r4 * r4);
  double delta = bb * bb - 4.0 * aa * cc;
  if (delta < 0.0) return std::nullopt;
  if (delta > 0.0) delta = std::sqrt(delta);
  double r;
  if (aa != 0.0) {
    const double rs1 = (-bb + delta) / (2.0 * aa);
    const double rs2 = (-bb - delta) / (2.0 * aa);
    if (rs1 <= 0 && rs2 <= 0) return std::nullopt;
    if (rs1 <= 0) {
      r = rs2;
    } else if (rs2 <= 0) {
      r = rs1;
    } else {
      r = rs2 < rs1 ? rs2 : rs1;
    }
  } else {
    if (bb == 0.0) return std::nullopt;
    r = -cc / bb;
    if (r <= 0.0) return std::nullopt;
  }
  return Sphere{{alx * r + bex, aly * r + bey, alz * r + bez}, r};
}

/// The sphere touching three spheres and a plane (origin o, normal d) (ESyS's Sphere3D::FillInWP).
std::optional<Sphere> fill_in_wall(const Vec& ip1, const Vec& ip2, const Vec& ip3, const Vec& o, const Vec& d,
                                   double r1, double r2, double r3) {
  const double ox = o[0], oy = o[1], oz = o[2];
  const double x3 = ip3[0] - ox, y3 = ip3[1] - oy, z3 = ip3[2] - oz;
  const double x2 = ip2[0] - ox, y2 = ip2[1] - oy, z2 = ip2[2] - oz;
  const double x1 = ip1[0] - ox, y1 = ip1[1] - oy, z1 = ip1[2] - oz;
  const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  double wx = d[0] / n, wy = d[1] / n, wz = d[2] / n;
  if ((x1 * wx + y1 * wy + z1 * wz) < 0) {
    wx = wx * -1.0;
    wy = wy * -1.0;
    wz = wz * -1.0;
  }
  if ((x2 * wx + y2 * wy + z2 * wz) < 0 || (x3 * wx + y3 * wy + z3 * wz) < 0) return std::nullopt;
  double s = 2.0 * (r2 - r1);
  const double a12x = 2.0 * x2 - 2.0 * x1 + s * wx, a12y = 2.0 * y2 - 2.0 * y1 + s * wy;
  const double a12z = 2.0 * z2 - 2.0 * z1 + s * wz;
  s = 2.0 * (r3 - r1);
  const double a13x = 2.0 * x3 - 2.0 * x1 + s * wx, a13y = 2.0 * y3 - 2.0 * y1 + s * wy;
  const double a13z = 2.0 * z3 - 2.0 * z1 + s * wz;
  const double p11 = x1 * x1 + y1 * y1 + z1 * z1;
  const double b12 = p11 - (x2 * x2 + y2 * y2 + z2 * z2) + r2 * r2 - r1 * r1;
  const double b13 = p11 - (x3 * x3 + y3 * y3 + z3 * z3) + r3 * r3 - r1 * r1;
  const double cx = a12z * a13y - a13z * a12y;
  const double cy = a12y * a13x - a13y * a12x;
  const double cz = a12z * a13x - a13z * a12x;
  const double dx = b12 * a13y - b13 * a12y;
  const double dy = b12 * a13x - b13 * a12x;
  if (cy == 0.0) return std::nullopt;
  const double ax = dx / cy, ay = -dy / cy, az = 0.0;
  const double bx = cx / cy, by = -cz / cy, bz = 1.0;
  const double bw = bx * wx + by * wy + bz * wz;
  const double aw_r3 = (ax * wx + ay * wy + az * wz) + r3;
  const double aa = (bx * bx + by * by + bz * bz) - bw * bw;
  const double bb = 2.0 * (bx * (ax - x3) + by * (ay - y3) + bz * (az - z3)) - 2.0 * bw * aw_r3;
  const double cc = ((x3 * x3 + y3 * y3 + z3 * z3) - 2.0 * (x3 * ax + y3 * ay + z3 * az) +
                     (ax * ax + ay * ay + az * az) - aw_r3 * aw_r3);
  double delta = bb * bb - 4.0 * aa * cc;
  if (delta < 0.0) return std::nullopt;
  if (delta > 0.0) delta = std::sqrt(delta);
  double m1z, m2z;
  if (aa != 0) {
    m1z = (-bb + delta) / (2.0 * aa);
    m2z = (-bb - delta) / (2.0 * aa);
  } else {
    if (bb == 0.0) return std::nullopt;
    m1z = -cc / bb;
    m2z = m1z;
  }
  const Vec m1 = {ax + bx * m1z, ay + by * m1z, az + bz * m1z};
  const Vec m2 = {ax + bx * m2z, ay + by * m2z, az + bz * m2z};
  const double rs1 = m1[0] * wx + m1[1] * wy + m1[2] * wz;
  const double rs2 = m2[0] * wx + m2[1] * wy + m2[2] * wz;
  if (rs1 <= 0 && rs2 <= 0) return std::nullopt;
  const bool first = !(rs1 <= 0) && (rs2 <= 0 || rs1 < rs2);
  const Vec& m = first ? m1 : m2;
  return Sphere{{ox + m[0], oy + m[1], oz + m[2]}, first ? rs1 : rs2};
}

struct Wall {
  Vec origin, normal;
  double dist;
  int axis;
};

class EsysBoxPacker {
 public:
  EsysBoxPacker(const Vec& lo, const Vec& hi, double rmin, double rmax, double cubic, int max_fails,
                double tol)
      : lo_(lo), hi_(hi), rmin_(rmin), rmax_(rmax), cubic_(cubic), max_fails_(max_fails), tol_(tol) {
    cell_ = 8.0 * rmin_;
    for (int a = 0; a < 3; ++a)
      dims_[a] = std::max(static_cast<int>(std::floor((hi_[a] - lo_[a]) / cell_)), 1);
    cells_.resize(std::size_t(dims_[0]) * std::size_t(dims_[1]) * std::size_t(dims_[2]));
  }

  /// Packs the box (again around the spheres there, as ESyS); every sphere so far, by id: (x, y, z, r) lists.
  std::array<std::vector<double>, 4> generate(EsysStream& rng) {
    cubic_packing(rng);
    random_fill(rng);
    std::array<std::vector<double>, 4> out;
    for (const Sphere& s : spheres_) {
      for (int a = 0; a < 3; ++a) out[a].push_back(s.c[a]);
      out[3].push_back(s.r);
    }
    return out;
  }

 private:
  // -- the cell table
  int clamp_index(double v, int a) const {
    const double f = std::floor((v - lo_[a]) / cell_);
    if (!(f > 0.0)) return 0;  // (NaN: never reached, the fits' checks come first)
    return f >= double(dims_[a] - 1) ? dims_[a] - 1 : static_cast<int>(f);
  }
  /// Calls f(cell) for each cell within `radius` of c, in (i, j, k) order.
  template <class F>
  void cell_range(const Vec& c, double radius, F&& f) const {
    int i0[3], i1[3];
    for (int a = 0; a < 3; ++a) {
      i0[a] = clamp_index(c[a] - radius, a);
      i1[a] = clamp_index(c[a] + radius, a);
    }
    for (int i = i0[0]; i <= i1[0]; ++i)
      for (int j = i0[1]; j <= i1[1]; ++j) {
        const std::size_t base =
            (std::size_t(i) * std::size_t(dims_[1]) + std::size_t(j)) * std::size_t(dims_[2]);
        for (int k = i0[2]; k <= i1[2]; ++k) f(cells_[base + std::size_t(k)]);
      }
  }
  void insert(const Sphere& s) {
    const std::int32_t n = static_cast<std::int32_t>(spheres_.size());
    spheres_.push_back(s);
    int i0[3], i1[3];
    for (int a = 0; a < 3; ++a) {
      i0[a] = clamp_index(s.c[a] - s.r, a);
      i1[a] = clamp_index(s.c[a] + s.r, a);
    }
    for (int i = i0[0]; i <= i1[0]; ++i)
      for (int j = i0[1]; j <= i1[1]; ++j) {
        const std::size_t base =
            (std::size_t(i) * std::size_t(dims_[1]) + std::size_t(j)) * std::size_t(dims_[2]);
        for (int k = i0[2]; k <= i1[2]; ++k) cells_[base + std::size_t(k)].push_back(n);
      }
  }

  // -- validity
  bool fits_box(double x, double y, double z, double r) const {
    const double t = tol_;
    const Vec pts[6] = {{x - r, y - 0.0, z - 0.0}, {x + r, y + 0.0, z + 0.0}, {x - 0.0, y - r, z - 0.0},
                        {x + 0.0, y + r, z + 0.0}, {x - 0.0, y - 0.0, z - r}, {x + 0.0, y + 0.0, z + r}};
    for (const Vec& p : pts) {
      if (!(lo_[0] <= p[0] + t && lo_[1] <= p[1] + t && lo_[2] <= p[2] + t && hi_[0] >= p[0] - t &&
            hi_[1] >= p[1] - t && hi_[2] >= p[2] - t))
        return false;
    }
    return true;
  }
  bool fits_neighbours(double x, double y, double z, double r) const {
    const double t = tol_;
    bool ok = true;
    cell_range({x, y, z}, r + t, [&](const std::vector<std::int32_t>& cell) {
      if (!ok) return;
      for (const std::int32_t n : cell) {
        const Sphere& q = spheres_[std::size_t(n)];
        const double dx = x - q.c[0], dy = y - q.c[1], dz = z - q.c[2];
        const double s = (r + q.r) - t;
        if (dx * dx + dy * dy + dz * dz < s * s) {
          ok = false;
          return;
        }
      }
    });
    return ok;
  }
  bool valid(const Sphere& s) const {
    return rmin_ <= s.r && s.r <= rmax_ && fits_box(s.c[0], s.c[1], s.c[2], s.r) &&
           fits_neighbours(s.c[0], s.c[1], s.c[2], s.r);
  }

  // -- the two stages
  void cubic_packing(EsysStream& rng) {
    const double R = cubic_;
    const Vec size = {hi_[0] - lo_[0], hi_[1] - lo_[1], hi_[2] - lo_[2]};
    // Python's round(): halves to even, as nearbyint in the default rounding mode
    int nx = std::max(1, static_cast<int>(std::nearbyint((size[0] - (R / 4.0)) / (R * 2.0))));
    const int ny = std::max(1, static_cast<int>(std::nearbyint(size[1] / (R * 2.0 * std::sqrt(2.0 / 3.0)))));
    const int nz = std::max(1, static_cast<int>(std::nearbyint(size[2] / (R * std::sqrt(3.0)))));
    if (nz > 1 && ny > 1) nx -= 1;
    const double x0 = lo_[0] + R, y0 = lo_[1] + R, z0 = lo_[2] + R;
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < nz; ++j)
        for (int k = 0; k < ny; ++k) {
          const double x = x0 + (double(i) + 0.5 * double(j % 2) + 0.5 * double(k % 2)) * R * 2.0;
          const double y = y0 + (double(k) * 2.0 * std::sqrt(2.0 / 3.0)) * R;
          const double z = z0 + ((double(j) + double(k % 2) / 3.0) * std::sqrt(3.0)) * R;
          const double r = rmin_ + (rmax_ - rmin_) * rng.uniform();
          if (fits_box(x, y, z, r) && fits_neighbours(x, y, z, r)) insert({{x, y, z}, r});
        }
  }

  /// The ids of the spheres in the cells within radius of c, each once, ascending (ESyS sorts its list by
  /// address, which follows the ids).
  void unique(const Vec& c, double radius, std::vector<std::int32_t>& ids) const {
    ids.clear();
    int cells = 0;
    cell_range(c, radius, [&](const std::vector<std::int32_t>& cell) {
      ids.insert(ids.end(), cell.begin(), cell.end());
      ++cells;
    });
    if (cells > 1) {  // (one cell's ids are appended in ascending order)
      std::sort(ids.begin(), ids.end());
      ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    }
  }

  /// The (up to) four closest spheres, by distance minus radius, among those ESyS's table offers (ties: the
  /// lower id first).
  std::vector<std::int32_t> closest(const Vec& c, double r) {
    const double t = tol_;
    unique(c, t, ids_);
    if (ids_.size() < 4) {
      unique(c, r + t, ids_);
      if (ids_.size() < 4) unique(c, rmax_ + t, ids_);
    }
    if (ids_.size() <= 1) return ids_;
    keyed_.clear();
    for (const std::int32_t n : ids_) {
      const Sphere& q = spheres_[std::size_t(n)];
      const double dx = q.c[0] - c[0], dy = q.c[1] - c[1], dz = q.c[2] - c[2];
      keyed_.push_back({std::sqrt(dx * dx + dy * dy + dz * dz) - q.r, n});
    }
    const std::size_t m = std::min<std::size_t>(4, keyed_.size());
    std::partial_sort(
        keyed_.begin(), keyed_.begin() + std::ptrdiff_t(m), keyed_.end(),
        [](const Keyed& a, const Keyed& b) { return a.key < b.key || (a.key == b.key && a.id < b.id); });
    std::vector<std::int32_t> out(m);
    for (std::size_t k = 0; k < m; ++k) out[k] = keyed_[k].id;
    return out;
  }

  /// The closest wall; on ties the first in ESyS's order y, x, z (min then max).
  Wall closest_wall(const Vec& c) const {
    static constexpr int kAxis[6] = {1, 1, 0, 0, 2, 2};
    Wall best{};
    bool have = false;
    for (int w = 0; w < 6; ++w) {
      const int axis = kAxis[w];
      const bool low = w % 2 == 0;
      const Vec& origin = low ? lo_ : hi_;
      const double d = std::fabs(c[std::size_t(axis)] - origin[std::size_t(axis)]);
      if (!have || d < best.dist) {
        Vec normal = {0.0, 0.0, 0.0};
        normal[std::size_t(axis)] = low ? 1.0 : -1.0;
        best = {origin, normal, d, axis};
        have = true;
      }
    }
    return best;
  }

  void random_fill(EsysStream& rng) {
    int last_fails = 0;
    while (last_fails < max_fails_) {
      int fails = 0;
      std::optional<Sphere> fit;
      while (!fit && fails < max_fails_) {
        // z first: ESyS's compiled Vec3(random, random, random) evaluates its arguments right to left
        const double z = lo_[2] + (hi_[2] - lo_[2]) * rng.uniform();
        const double y = lo_[1] + (hi_[1] - lo_[1]) * rng.uniform();
        const double x = lo_[0] + (hi_[0] - lo_[0]) * rng.uniform();
        const double r = rmin_ + (rmax_ - rmin_) * rng.uniform();
        const Vec c = {x, y, z};
        const std::vector<std::int32_t> nb = closest(c, r);
        const Wall wall = closest_wall(c);
        fit = fit_surface(c, r, nb);
        if (!fit) fit = fit_four(c, nb, wall);
        if (!fit) fit = fit_wall(c, nb, wall);
        ++fails;
      }
      last_fails = fails;
      if (!fit) break;
      insert(*fit);
    }
  }

  // -- the fitters
  double gap(const Vec& p, std::int32_t n) const {
    const Sphere& q = spheres_[std::size_t(n)];
    const double dx = p[0] - q.c[0], dy = p[1] - q.c[1], dz = p[2] - q.c[2];
    return std::sqrt(dx * dx + dy * dy + dz * dz) - q.r;
  }

  std::optional<Sphere> fit_surface(const Vec& c, double r, const std::vector<std::int32_t>& nb) const {
    Sphere s{c, r};
    if (!nb.empty()) {
      const Sphere& q = spheres_[std::size_t(nb[0])];
      const double dx = c[0] - q.c[0], dy = c[1] - q.c[1], dz = c[2] - q.c[2];
      if (std::sqrt(dx * dx + dy * dy + dz * dz) < r + q.r) {
        const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
        if (d > 0.0) {
          const double k = q.r + r;
          s.c = {q.c[0] + (dx / d) * k, q.c[1] + (dy / d) * k, q.c[2] + (dz / d) * k};
        }
      }
    }
    if (valid(s)) return s;
    return std::nullopt;
  }

  /// The candidate's centre, moved onto the surface of neighbour n if it lies inside n; none if at n's
  /// centre.
  std::optional<Vec> moved_inside(const Vec& c, std::int32_t n) const {
    const Sphere& q = spheres_[std::size_t(n)];
    const double dx = c[0] - q.c[0], dy = c[1] - q.c[1], dz = c[2] - q.c[2];
    const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (!(d > 0.0)) return std::nullopt;
    if (d < q.r) {
      const double s = q.r / d;
      return Vec{q.c[0] + dx * s, q.c[1] + dy * s, q.c[2] + dz * s};
    }
    return c;
  }

  std::optional<Sphere> fit_four(const Vec& c, const std::vector<std::int32_t>& nb, const Wall& wall) const {
    if (nb.size() <= 3) return std::nullopt;
    const std::optional<Vec> p = moved_inside(c, nb[0]);
    if (!p) return std::nullopt;
    // the distance to the wall chosen for the candidate, from the (maybe moved) centre
    const std::size_t a = std::size_t(wall.axis);
    const double wall_p = std::fabs((*p)[a] - wall.origin[a]);
    if (!(wall_p > gap(*p, nb[3]))) return std::nullopt;
    const Sphere &s0 = spheres_[std::size_t(nb[0])], &s1 = spheres_[std::size_t(nb[1])],
                 &s2 = spheres_[std::size_t(nb[2])], &s3 = spheres_[std::size_t(nb[3])];
    std::optional<Sphere> fit = fill_in_4(s0.c, s1.c, s2.c, s3.c, s0.r, s1.r, s2.r, s3.r);
    if (!fit || !valid(*fit)) return std::nullopt;
    return fit;
  }

  std::optional<Sphere> fit_wall(const Vec& c, const std::vector<std::int32_t>& nb, const Wall& wall) const {
    if (nb.size() < 3) return std::nullopt;
    const Sphere& q = spheres_[std::size_t(nb[0])];
    const double dx = c[0] - q.c[0], dy = c[1] - q.c[1], dz = c[2] - q.c[2];
    if (!(std::sqrt(dx * dx + dy * dy + dz * dz) > 0.0)) return std::nullopt;
    if (nb.size() > 3 && !(wall.dist < gap(c, nb[3]))) return std::nullopt;
    const Sphere &s0 = spheres_[std::size_t(nb[0])], &s1 = spheres_[std::size_t(nb[1])],
                 &s2 = spheres_[std::size_t(nb[2])];
    std::optional<Sphere> fit = fill_in_wall(s0.c, s1.c, s2.c, wall.origin, wall.normal, s0.r, s1.r, s2.r);
    if (!fit || !valid(*fit)) return std::nullopt;
    return fit;
  }

  struct Keyed {
    double key;
    std::int32_t id;
  };

  Vec lo_, hi_;
  double rmin_, rmax_, cubic_;
  int max_fails_;
  double tol_, cell_ = 0.0;
  int dims_[3] = {1, 1, 1};
  std::vector<std::vector<std::int32_t>> cells_;  // the ids of the spheres reaching into each cell, ascending
  std::vector<Sphere> spheres_;                   // by id
  std::vector<std::int32_t> ids_;                 // (scratch)
  std::vector<Keyed> keyed_;                      // (scratch)
};

}  // namespace

void bind_esys_packer(pybind11::module_& m) {
  namespace py = pybind11;
  py::class_<EsysStream>(
      m, "EsysStream",
      "The ESyS front end's random stream (basalt.esys.packer): MT19937 seeded 5489, each number "
      "a 32-bit draw / 2^32, as ESyS-Particle's packers draw them.")
      .def(py::init<>())
      .def("uniform", &EsysStream::uniform, "The next number in [0, 1).");
  py::class_<EsysBoxPacker>(
      m, "EsysBoxPacker",
      "ESyS-Particle 2.3.5's RandomBoxPacker of a 3-D box (basalt.esys.packer), bit for bit.")
      .def(py::init<const Vec&, const Vec&, double, double, double, int, double>(), py::arg("lo"),
           py::arg("hi"), py::arg("min_radius"), py::arg("max_radius"), py::arg("cubic_radius"),
           py::arg("max_fails"), py::arg("tolerance"))
      .def("generate", &EsysBoxPacker::generate, py::arg("stream"),
           "Packs (again around the spheres there); every sphere so far by id, as lists x, y, z, r.");
}

}  // namespace basalt::python
