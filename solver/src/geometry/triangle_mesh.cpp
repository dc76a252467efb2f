// Sphere contacts with a triangle mesh, each touching point of the surface counted once
// (basalt/solver/geometry/triangle_mesh.hpp, docs/mesh-walls.md).
#include "basalt/solver/geometry/triangle_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

namespace basalt::solver {

namespace {

using Vec3 = ContactMesh::Vec3;

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec3 mul(double s, const Vec3& a) { return {s * a[0], s * a[1], s * a[2]}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
Vec3 unit(const Vec3& a) {
  const double n = norm(a);
  return n > 0 ? mul(1 / n, a) : Vec3{0, 0, 0};
}

/// Where on a triangle its closest point to p lies: 0 interior, 1 + k edge k (vertex k to k+1), 4 + k vertex
/// k.
enum Region : int { kFace = 0, kEdge0 = 1, kVertex0 = 4 };

/// Closest point of triangle (a, b, c) to p and its region (Ericson, Real-Time Collision Detection, 5.1.5).
Region closest_point(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Vec3& q) {
  const Vec3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return q = a, Region(kVertex0 + 0);
  const Vec3 bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return q = b, Region(kVertex0 + 1);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return q = add(a, mul(d1 / (d1 - d3), ab)), Region(kEdge0 + 0);
  const Vec3 cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return q = c, Region(kVertex0 + 2);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return q = add(a, mul(d2 / (d2 - d6), ac)), Region(kEdge0 + 2);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return q = add(b, mul((d4 - d3) / ((d4 - d3) + (d5 - d6)), sub(c, b))), Region(kEdge0 + 1);
  const double denom = 1 / (va + vb + vc);
  q = add(a, add(mul(vb * denom, ab), mul(vc * denom, ac)));
  return kFace;
}

bool contains(std::span<const std::int32_t> sorted, std::int32_t x) {
  return std::binary_search(sorted.begin(), sorted.end(), x);
}

// Rounding slack of the local-minimum tests: relative to the distance, plus an absolute part relative to
// the mesh size (a centre exactly above an edge must pass the edge's test whatever the rounding).
constexpr double kRelativeSlack = 1e-9;
constexpr double kAbsoluteSlack = 1e-12;

}  // namespace

ContactMesh::ContactMesh(std::vector<Vec3> vertices, std::vector<Triangle> triangles, Options options)
    : options_(options), v_(std::move(vertices)), tri_(std::move(triangles)) {
  if (!(options_.cell_size >= 0)) throw std::invalid_argument("ContactMesh: cell_size must be >= 0");
  const auto nv = static_cast<std::int64_t>(v_.size());
  for (std::size_t t = 0; t < tri_.size(); ++t) {
    const auto& tr = tri_[t];
    for (auto i : tr)
      if (i < 0 || i >= nv)
        throw std::invalid_argument("ContactMesh: triangle " + std::to_string(t) + " has vertex index " +
                                    std::to_string(i) + " out of range");
    if (tr[0] == tr[1] || tr[1] == tr[2] || tr[0] == tr[2])
      throw std::invalid_argument("ContactMesh: triangle " + std::to_string(t) + " repeats a vertex");
  }
  for (const auto& x : v_)
    for (double c : x)
      if (!std::isfinite(c)) throw std::invalid_argument("ContactMesh: a vertex coordinate is not finite");
  build_topology();
  build_grid();
}

void ContactMesh::build_topology() {
  const std::size_t nt = tri_.size(), nv = v_.size();
  n_.resize(nt);
  inward_.resize(nt);
  box_.resize(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& a = v_[tri_[t][0]];
    const auto& b = v_[tri_[t][1]];
    const auto& c = v_[tri_[t][2]];
    const Vec3 x = cross(sub(b, a), sub(c, a));
    if (!(norm(x) > 0))
      throw std::invalid_argument("ContactMesh: triangle " + std::to_string(t) + " has zero area");
    n_[t] = unit(x);
    for (int k = 0; k < 3; ++k) {
      const auto& p = v_[tri_[t][k]];
      const auto& q = v_[tri_[t][(k + 1) % 3]];
      inward_[t][k] = unit(cross(n_[t], sub(q, p)));
    }
    for (int d = 0; d < 3; ++d) {
      box_[t][0][d] = std::min({a[d], b[d], c[d]});
      box_[t][1][d] = std::max({a[d], b[d], c[d]});
    }
  }

  // Edges: one per pair of vertices, numbered in order of first appearance.
  std::map<std::pair<std::int32_t, std::int32_t>, std::int32_t> index;
  tri_edge_.resize(nt);
  std::vector<std::vector<std::int32_t>> et;
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const auto i = tri_[t][k], j = tri_[t][(k + 1) % 3];
      const auto key = std::minmax(i, j);
      auto [it, fresh] =
          index.try_emplace({key.first, key.second}, static_cast<std::int32_t>(edge_v_.size()));
      if (fresh) {
        edge_v_.push_back({key.first, key.second});
        et.emplace_back();
      }
      tri_edge_[t][k] = it->second;
      et[static_cast<std::size_t>(it->second)].push_back(static_cast<std::int32_t>(t));
    }
  auto flatten = [](const std::vector<std::vector<std::int32_t>>& lists, std::vector<std::int32_t>& off,
                    std::vector<std::int32_t>& flat) {
    off.assign(1, 0);
    flat.clear();
    for (auto l : lists) {
      std::sort(l.begin(), l.end());
      l.erase(std::unique(l.begin(), l.end()), l.end());
      flat.insert(flat.end(), l.begin(), l.end());
      off.push_back(static_cast<std::int32_t>(flat.size()));
    }
  };
  flatten(et, edge_tri_off_, edge_tri_);
  std::vector<std::vector<std::int32_t>> vt(nv), ve(nv);
  for (std::size_t t = 0; t < nt; ++t)
    for (auto i : tri_[t]) vt[static_cast<std::size_t>(i)].push_back(static_cast<std::int32_t>(t));
  for (std::size_t e = 0; e < edge_v_.size(); ++e)
    for (auto i : edge_v_[e]) ve[static_cast<std::size_t>(i)].push_back(static_cast<std::int32_t>(e));
  flatten(vt, vtx_tri_off_, vtx_tri_);
  flatten(ve, vtx_edge_off_, vtx_edge_);

  // Pseudo-normals (Baerentzen and Aanaes 2005): the sum of the adjacent face normals for an edge, the
  // angle-weighted sum for a vertex; their sign tells the side of a point closest to that feature.
  edge_normal_.assign(edge_v_.size(), Vec3{0, 0, 0});
  for (std::size_t e = 0; e < edge_v_.size(); ++e)
    for (auto t : edge_triangles(e)) edge_normal_[e] = add(edge_normal_[e], n_[static_cast<std::size_t>(t)]);
  for (auto& n : edge_normal_) n = unit(n);
  vertex_normal_.assign(nv, Vec3{0, 0, 0});
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const auto& p = v_[tri_[t][k]];
      const Vec3 u = unit(sub(v_[tri_[t][(k + 1) % 3]], p)), w = unit(sub(v_[tri_[t][(k + 2) % 3]], p));
      const double angle = std::acos(std::clamp(dot(u, w), -1.0, 1.0));
      auto& n = vertex_normal_[static_cast<std::size_t>(tri_[t][k])];
      n = add(n, mul(angle, n_[t]));
    }
  for (auto& n : vertex_normal_) n = unit(n);

  lo_ = hi_ = v_.empty() ? Vec3{0, 0, 0} : v_[0];
  for (const auto& x : v_)
    for (int d = 0; d < 3; ++d) lo_[d] = std::min(lo_[d], x[d]), hi_[d] = std::max(hi_[d], x[d]);
  scale_ = std::max(norm(sub(hi_, lo_)), std::max({std::abs(lo_[0]), std::abs(lo_[1]), std::abs(lo_[2]),
                                                   std::abs(hi_[0]), std::abs(hi_[1]), std::abs(hi_[2])}));
  if (!(scale_ > 0)) scale_ = 1;
}

void ContactMesh::build_grid() {
  const std::size_t nt = tri_.size();
  double cell = options_.cell_size;
  if (cell == 0) {
    double sum = 0;
    for (const auto& b : box_) sum += std::max({b[1][0] - b[0][0], b[1][1] - b[0][1], b[1][2] - b[0][2]});
    cell = nt ? sum / static_cast<double>(nt) : 1;
  }
  cell = std::max(cell, 1e-9 * scale_);
  // At most ~4 cells per triangle (and at least one cell).
  const double cap = 4.0 * static_cast<double>(nt) + 64;
  for (;;) {
    double total = 1;
    for (int d = 0; d < 3; ++d) {
      dims_[d] = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil((hi_[d] - lo_[d]) / cell)));
      total *= static_cast<double>(dims_[d]);
    }
    if (total <= cap) break;
    cell *= 1.25;
  }
  cell_ = cell;
  grid_lo_ = lo_;
  auto cell_range = [&](const std::array<Vec3, 2>& b, std::array<std::int64_t, 3>& c0,
                        std::array<std::int64_t, 3>& c1) {
    for (int d = 0; d < 3; ++d) {
      c0[d] = std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor((b[0][d] - grid_lo_[d]) / cell_)),
                                       0, dims_[d] - 1);
      c1[d] = std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor((b[1][d] - grid_lo_[d]) / cell_)),
                                       0, dims_[d] - 1);
    }
  };
  const std::int64_t ncell = dims_[0] * dims_[1] * dims_[2];
  cell_off_.assign(static_cast<std::size_t>(ncell + 1), 0);
  auto for_cells = [&](std::size_t t, auto&& f) {
    std::array<std::int64_t, 3> c0{}, c1{};
    cell_range(box_[t], c0, c1);
    for (auto i = c0[0]; i <= c1[0]; ++i)
      for (auto j = c0[1]; j <= c1[1]; ++j)
        for (auto k = c0[2]; k <= c1[2]; ++k) f((i * dims_[1] + j) * dims_[2] + k);
  };
  for (std::size_t t = 0; t < nt; ++t)
    for_cells(t, [&](std::int64_t c) { ++cell_off_[static_cast<std::size_t>(c + 1)]; });
  for (std::size_t c = 0; c < static_cast<std::size_t>(ncell); ++c) cell_off_[c + 1] += cell_off_[c];
  cell_tri_.resize(static_cast<std::size_t>(cell_off_.back()));
  auto fill = cell_off_;
  for (std::size_t t = 0; t < nt; ++t)
    for_cells(t, [&](std::int64_t c) {
      cell_tri_[static_cast<std::size_t>(fill[static_cast<std::size_t>(c)]++)] = static_cast<std::int32_t>(t);
    });
}

std::size_t ContactMesh::boundary_edges() const {
  std::size_t n = 0;
  for (std::size_t e = 0; e < edge_v_.size(); ++e) n += edge_triangles(e).size() == 1;
  return n;
}

std::size_t ContactMesh::nonmanifold_edges() const {
  std::size_t n = 0;
  for (std::size_t e = 0; e < edge_v_.size(); ++e) n += edge_triangles(e).size() > 2;
  return n;
}

void ContactMesh::set_pose(const RigidTransform& pose) {
  std::array<std::array<double, 3>, 3> rot{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  if (pose.angle != 0) {
    const Vec3 u = unit(pose.axis);
    if (norm(u) == 0) throw std::invalid_argument("ContactMesh::set_pose: rotation about a zero axis");
    const double c = std::cos(pose.angle), s = std::sin(pose.angle), C = 1 - c;
    const double x = u[0], y = u[1], z = u[2];
    rot = {{{c + x * x * C, x * y * C - z * s, x * z * C + y * s},
            {y * x * C + z * s, c + y * y * C, y * z * C - x * s},
            {z * x * C - y * s, z * y * C + x * s, c + z * z * C}}};
  }
  pose_ = pose;
  rot_ = rot;
  moved_ = pose.angle != 0 || pose.translation != Vec3{0, 0, 0};
}

ContactMesh::Vec3 ContactMesh::rotate(const Vec3& x) const {
  if (!moved_) return x;
  return {dot(rot_[0], x), dot(rot_[1], x), dot(rot_[2], x)};
}

ContactMesh::Vec3 ContactMesh::to_world(const Vec3& x) const {
  if (!moved_) return x;
  return add(add(rotate(sub(x, pose_.axis_point)), pose_.axis_point), pose_.translation);
}

ContactMesh::Vec3 ContactMesh::to_rest(const Vec3& x) const {
  if (!moved_) return x;
  const Vec3 y = sub(sub(x, pose_.translation), pose_.axis_point);
  const Vec3 r{rot_[0][0] * y[0] + rot_[1][0] * y[1] + rot_[2][0] * y[2],
               rot_[0][1] * y[0] + rot_[1][1] * y[1] + rot_[2][1] * y[2],
               rot_[0][2] * y[0] + rot_[1][2] * y[1] + rot_[2][2] * y[2]};  // R^T y
  return add(r, pose_.axis_point);
}

void ContactMesh::rest_candidates(const Vec3& p, double reach, std::vector<std::int32_t>& out) const {
  out.clear();
  std::array<std::int64_t, 3> c0{}, c1{};
  for (int d = 0; d < 3; ++d) {
    if (p[d] + reach < lo_[d] || p[d] - reach > hi_[d]) return;
    c0[d] = std::clamp<std::int64_t>(
        static_cast<std::int64_t>(std::floor((p[d] - reach - grid_lo_[d]) / cell_)), 0, dims_[d] - 1);
    c1[d] = std::clamp<std::int64_t>(
        static_cast<std::int64_t>(std::floor((p[d] + reach - grid_lo_[d]) / cell_)), 0, dims_[d] - 1);
  }
  for (auto i = c0[0]; i <= c1[0]; ++i)
    for (auto j = c0[1]; j <= c1[1]; ++j)
      for (auto k = c0[2]; k <= c1[2]; ++k) {
        const auto c = static_cast<std::size_t>((i * dims_[1] + j) * dims_[2] + k);
        for (auto o = cell_off_[c]; o < cell_off_[c + 1]; ++o) {
          const auto t = cell_tri_[static_cast<std::size_t>(o)];
          const auto& b = box_[static_cast<std::size_t>(t)];
          bool near = true;
          for (int d = 0; d < 3; ++d) near = near && p[d] + reach >= b[0][d] && p[d] - reach <= b[1][d];
          if (near) out.push_back(t);
        }
      }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

void ContactMesh::candidates(const Vec3& centre, double reach, std::vector<std::int32_t>& out) const {
  rest_candidates(to_rest(centre), reach, out);
}

std::size_t ContactMesh::contacts(const Vec3& centre, double radius, std::vector<MeshContact>& out) const {
  thread_local std::vector<std::int32_t> cand;
  const Vec3 p = to_rest(centre);
  rest_candidates(p, radius, cand);
  return contacts_from(p, radius, cand, out);
}

std::size_t ContactMesh::contacts_brute_force(const Vec3& centre, double radius,
                                              std::vector<MeshContact>& out) const {
  thread_local std::vector<std::int32_t> cand;
  const Vec3 p = to_rest(centre);
  cand.clear();
  for (std::size_t t = 0; t < tri_.size(); ++t) {
    bool near = true;
    for (int d = 0; d < 3; ++d)
      near = near && p[d] + radius >= box_[t][0][d] && p[d] - radius <= box_[t][1][d];
    if (near) cand.push_back(static_cast<std::int32_t>(t));
  }
  return contacts_from(p, radius, cand, out);
}

std::size_t ContactMesh::contacts_from(const Vec3& p, double r, const std::vector<std::int32_t>& cand,
                                       std::vector<MeshContact>& out) const {
  thread_local std::vector<std::int32_t> face_region, edges, vertices, edge_ok;
  face_region.clear(), edges.clear(), vertices.clear(), edge_ok.clear();
  const std::size_t first = out.size();
  const bool one_sided = options_.sides == Sides::one;
  const double r2 = r * r;
  const double abs_slack = kAbsoluteSlack * scale_;

  // 1. Faces: a closest point in a triangle's interior is always a contact.
  for (const auto t : cand) {
    const auto ts = static_cast<std::size_t>(t);
    const auto& a = v_[tri_[ts][0]];
    Vec3 q;
    const Region region = closest_point(p, a, v_[tri_[ts][1]], v_[tri_[ts][2]], q);
    const Vec3 w = sub(p, q);
    if (dot(w, w) >= r2) continue;
    for (int k = 0; k < 3; ++k) edges.push_back(tri_edge_[ts][k]), vertices.push_back(tri_[ts][k]);
    if (region != kFace) continue;
    face_region.push_back(t);
    const double s = dot(sub(p, a), n_[ts]);  // signed distance to the plane
    if (std::abs(s) >= r || (one_sided && s <= 0)) continue;
    MeshContact c;
    c.point = sub(p, mul(s, n_[ts]));
    c.normal = s >= 0 ? n_[ts] : mul(-1, n_[ts]);
    c.distance = std::abs(s);
    c.overlap = r - c.distance;
    c.feature = MeshFeature::face;
    c.index = c.triangle = t;
    out.push_back(c);
  }
  std::sort(face_region.begin(), face_region.end());
  auto any_face = [&](std::span<const std::int32_t> tris) {
    for (auto t : tris)
      if (contains(face_region, t)) return true;
    return false;
  };

  // 2. Edges: once each, if no adjacent triangle has its closest point inside and the edge point is a
  // local minimum of the distance over the adjacent triangles (the centre does not lean into any of them).
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto e : edges) {
    const auto es = static_cast<std::size_t>(e);
    const auto tris = edge_triangles(es);
    if (any_face(tris)) continue;
    const auto& a = v_[edge_v_[es][0]];
    const Vec3 ab = sub(v_[edge_v_[es][1]], a);
    const double t = dot(sub(p, a), ab) / dot(ab, ab);
    if (!(t > 0 && t < 1)) continue;  // the closest point is a vertex
    const Vec3 q = add(a, mul(t, ab));
    const Vec3 w = sub(p, q);
    const double d = norm(w);
    if (d >= r) continue;
    const double slack = kRelativeSlack * d + abs_slack;
    bool local_min = true;
    for (const auto f : tris) {
      const auto fs = static_cast<std::size_t>(f);
      const int k = tri_edge_[fs][0] == e ? 0 : tri_edge_[fs][1] == e ? 1 : 2;
      if (dot(w, inward_[fs][k]) > slack) local_min = false;
    }
    if (!local_min) continue;
    edge_ok.push_back(e);
    if (one_sided && !(dot(w, edge_normal_[es]) > 0)) continue;
    MeshContact c;
    c.point = q;
    c.normal = d > 0 ? mul(1 / d, w) : edge_normal_[es];
    c.distance = d;
    c.overlap = r - d;
    c.feature = MeshFeature::edge;
    c.index = e;
    c.triangle = tris[0];
    out.push_back(c);
  }

  // 3. Vertices: once each, if no incident triangle or edge gave a contact and the vertex is a local
  // minimum of the distance over the triangles around it (the centre leans along none of its edges).
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  for (const auto v : vertices) {
    const auto vs = static_cast<std::size_t>(v);
    if (any_face(vertex_triangles(vs))) continue;
    const auto inc = vertex_edges(vs);
    bool blocked = false;
    for (auto e : inc) blocked = blocked || std::find(edge_ok.begin(), edge_ok.end(), e) != edge_ok.end();
    if (blocked) continue;
    const Vec3 w = sub(p, v_[vs]);
    const double d = norm(w);
    if (d >= r) continue;
    const double slack = kRelativeSlack * d + abs_slack;
    bool local_min = true;
    for (const auto e : inc) {
      const auto& ev = edge_v_[static_cast<std::size_t>(e)];
      const Vec3 u = unit(sub(v_[static_cast<std::size_t>(ev[0] == v ? ev[1] : ev[0])], v_[vs]));
      if (dot(w, u) > slack) local_min = false;
    }
    if (!local_min) continue;
    if (one_sided && !(dot(w, vertex_normal_[vs]) > 0)) continue;
    MeshContact c;
    c.point = v_[vs];
    c.normal = d > 0 ? mul(1 / d, w) : vertex_normal_[vs];
    c.distance = d;
    c.overlap = r - d;
    c.feature = MeshFeature::vertex;
    c.index = v;
    c.triangle = vertex_triangles(vs)[0];
    out.push_back(c);
  }

  // 4. Safety net against rounding: within a rounding-sized neighbourhood of a vertex, a face and an edge
  // or vertex not adjacent to it can both pass; such contacts (same point, same normal) are one.
  for (std::size_t i = first; i < out.size(); ++i)
    for (std::size_t j = i + 1; j < out.size();) {
      const double gap = norm(sub(out[i].point, out[j].point));
      if (gap <= 1e-6 * out[i].distance + 1e3 * abs_slack && dot(out[i].normal, out[j].normal) >= 1 - 1e-9)
        out.erase(out.begin() + static_cast<std::ptrdiff_t>(j));  // out[i]: face before edge before vertex
      else
        ++j;
    }

  for (std::size_t i = first; moved_ && i < out.size(); ++i) {
    out[i].point = to_world(out[i].point);
    out[i].normal = rotate(out[i].normal);
  }
  return out.size() - first;
}

}  // namespace basalt::solver
