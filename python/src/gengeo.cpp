// gengeo_fit: the inner loop of the ESyS front end's GenGeo packing (python/basalt/esys/gengeo.py,
// docs/esys.md "GenGeo"): the simplex search that fits a sphere to four objects (spheres or planes), each
// floating-point operation in the order GenGeo 1.4 makes it, so that the packing matches GenGeo's bit for bit.
// Compiled with -ffp-contract=off (python/CMakeLists.txt): a fused multiply-add would round differently.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <utility>

#include "bindings.hpp"

namespace basalt::python {
namespace {

using Vec = std::array<double, 3>;

// One object: a sphere (centre, radius) or a plane (a point, its unit normal).
struct Object {
  bool plane = false;
  double a[6] = {0, 0, 0, 0, 0, 0};
  double dist(const Vec& q) const {
    if (plane) {
      return std::fabs(((q[0] - a[0]) * a[3] + (q[1] - a[1]) * a[4]) + (q[2] - a[2]) * a[5]);
    }
    const double dx = q[0] - a[0], dy = q[1] - a[1], dz = q[2] - a[2];
    return std::sqrt((dx * dx + dy * dy) + dz * dz) - a[3];
  }
};

struct Fit {
  const Object* o = nullptr;
  Vec v[4] = {};
  double f[4] = {0, 0, 0, 0};

  double spread(const Vec& p) const {
    const double d1 = o[0].dist(p), d2 = o[1].dist(p), d3 = o[2].dist(p), d4 = o[3].dist(p);
    const double m = (((d1 + d2) + d3) + d4) * 0.25;
    const double a = m - d1, b = m - d2, c = m - d3, e = m - d4;
    return std::sqrt(((a * a + b * b) + c * c) + e * e);
  }
  void swap(int i, int j) {
    std::swap(v[i], v[j]);
    std::swap(f[i], f[j]);
  }
  // Vertices kept from the largest value (0) to the smallest (3); `!(x > y)` is GenGeo's comparison, NaN
  // included.
  void insert(const Vec& p, double fp, int n) {
    v[n] = p;
    f[n] = fp;
    int i = n;
    while (i <= 2 && !(f[i] > f[i + 1])) {
      swap(i, i + 1);
      ++i;
    }
    while (i > 0 && !(f[i - 1] > f[i])) {
      swap(i - 1, i);
      --i;
    }
  }
  Vec reflect(int j) const {
    double sx = 0.0, sy = 0.0, sz = 0.0;
    for (int k = 0; k < 4; ++k) {
      if (k == j) continue;
      sx += v[k][0];
      sy += v[k][1];
      sz += v[k][2];
    }
    return {(sx + sx) / 3.0 - v[j][0], (sy + sy) / 3.0 - v[j][1], (sz + sz) / 3.0 - v[j][2]};
  }
  void shrink() {
    const double cx = (((v[0][0] + v[1][0]) + v[2][0]) + v[3][0]) * 0.25;
    const double cy = (((v[0][1] + v[1][1]) + v[2][1]) + v[3][1]) * 0.25;
    const double cz = (((v[0][2] + v[1][2]) + v[2][2]) + v[3][2]) * 0.25;
    for (int k = 0; k < 4; ++k) {
      v[k] = {(v[k][0] - cx) * 0.5 + cx, (v[k][1] - cy) * 0.5 + cy, (v[k][2] - cz) * 0.5 + cz};
      f[k] = spread(v[k]);
    }
    for (int start = 0; start < 2; ++start) {  // two bubble passes, as GenGeo (not a full sort)
      for (int a = start; a < 3; ++a) {
        if (f[a + 1] > f[a]) swap(a, a + 1);
      }
    }
  }
};

// The fitted sphere (x, y, z, r) for objects given as (is_plane, 6 numbers), from `start`.
std::array<double, 4> gengeo_fit(const std::array<std::pair<bool, std::array<double, 6>>, 4>& objects,
                                 const Vec& start, int max_iter, double prec) {
  Object o[4];
  for (int i = 0; i < 4; ++i) {
    o[i].plane = objects[i].first;
    for (int k = 0; k < 6; ++k) o[i].a[k] = objects[i].second[k];
  }
  Fit s;
  s.o = o;
  for (auto& p : s.v) p = {0.0, 0.0, 0.0};
  const double x = start[0], y = start[1], z = start[2];
  s.insert(start, s.spread(start), 0);
  const Vec steps[3] = {{1.0 + x, 0.0 + y, 0.0 + z}, {0.0 + x, 1.0 + y, 0.0 + z}, {0.0 + x, 0.0 + y, 1.0 + z}};
  for (int n = 1; n <= 3; ++n) s.insert(steps[n - 1], s.spread(steps[n - 1]), n);
  if (s.f[0] > prec && (max_iter > 0 || max_iter == -1)) {
    for (int count = 0;;) {
      int j = 0;
      for (; j < 4; ++j) {
        const Vec p = s.reflect(j);
        const double fp = s.spread(p);
        if (s.f[j] > fp) {
          s.insert(p, fp, j);
          break;
        }
      }
      if (j == 4) s.shrink();
      ++count;
      if (!(s.f[3] > prec)) break;
      if (!(count < max_iter || max_iter == -1)) break;
    }
  }
  const Vec& c = s.v[3];
  const double d1 = o[0].dist(c), d2 = o[1].dist(c), d3 = o[2].dist(c), d4 = o[3].dist(c);
  double m = d1 < d2 ? d1 : d2;
  m = m < d3 ? m : d3;
  m = m < d4 ? m : d4;
  return {c[0], c[1], c[2], m - prec * 0.1};
}

}  // namespace

void bind_gengeo(pybind11::module_& m) {
  m.def("gengeo_fit", &gengeo_fit, pybind11::arg("objects"), pybind11::arg("start"), pybind11::arg("max_iter"),
        pybind11::arg("prec"),
        "The ESyS front end's GenGeo fit (basalt.esys.gengeo): the sphere (x, y, z, r) fitted to four objects, "
        "each (is_plane, (x, y, z, r, 0, 0) for a sphere or (px, py, pz, nx, ny, nz) for a plane), by GenGeo's "
        "simplex search from `start`.");
}

}  // namespace basalt::python
