// A closed triangle mesh as a volume (CGAL): read and checked with Polygon_mesh_processing, inside test
// with Side_of_triangle_mesh, distances and closest points with an AABB tree.
#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/IO/polygon_mesh_io.h>
#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "basalt/packer/error.hpp"
#include "basalt/packer/volume.hpp"

namespace basalt::packer {

namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<K::Point_3>;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
using Inside = CGAL::Side_of_triangle_mesh<Mesh, K>;

class MeshVolume final : public Volume {
 public:
  MeshVolume(Mesh mesh, std::string name) : mesh_(std::move(mesh)), name_(std::move(name)) {
    tree_.insert(faces(mesh_).first, faces(mesh_).second, mesh_);
    tree_.accelerate_distance_queries();
    inside_ = std::make_unique<Inside>(tree_);
    volume_ = CGAL::to_double(PMP::volume(mesh_));
    auto bb = tree_.bbox();
    bounds_ = {{bb.xmin(), bb.ymin(), bb.zmin()}, {bb.xmax(), bb.ymax(), bb.zmax()}};
    group_planes();
  }
  std::string description() const override {
    return fmt::format("mesh {} ({} triangles, volume {:.6g})", name_, mesh_.number_of_faces(), volume_);
  }
  Bounds bounds() const override { return bounds_; }
  double measure() const override { return volume_; }
  double signed_distance(const Vec3& x) const override {
    K::Point_3 p(x[0], x[1], x[2]);
    double d = std::sqrt(CGAL::to_double(tree_.squared_distance(p)));
    return (*inside_)(p) == CGAL::ON_UNBOUNDED_SIDE ? -d : d;
  }
  /// Each plane of the mesh (coplanar triangles grouped) is one flat piece: spheres touch the faces exactly
  /// and edges and corners behave like a box's.
  void pieces_near(const Vec3& x, double reach, std::vector<BoundaryPiece>& out) const override {
    K::Point_3 p(x[0], x[1], x[2]);
    if (tree_.squared_distance(p) > reach * reach) return;
    hits_.clear();
    const CGAL::Bbox_3 box(x[0] - reach, x[1] - reach, x[2] - reach, x[0] + reach, x[1] + reach,
                           x[2] + reach);
    tree_.all_intersected_primitives(box, std::back_inserter(hits_));
    const std::size_t first = out.size();
    for (auto f : hits_) {
      const int group = group_of_[f.idx()];
      bool seen = false;
      for (std::size_t k = first; k < out.size(); ++k) seen = seen || out[k].id == group;
      if (seen) continue;
      // Only faces whose plane's closest point to x lies on the face: mirroring across the plane of a face
      // beyond a concave edge would put the ghost inside the volume.
      const double d_face = std::sqrt(CGAL::to_double(CGAL::squared_distance(p, triangle(f))));
      const double d_plane = std::abs(planes_[group].distance(x));
      if (d_face <= reach && d_face - d_plane <= 1e-9 * (1 + d_face))
        out.push_back({group, true, planes_[group]});
    }
  }
  Plane tangent_plane(int id, const Vec3& x) const override {
    if (id >= 0) return planes_[id];
    return closest_tangent_plane(x);
  }
  Plane closest_tangent_plane(const Vec3& x) const {
    K::Point_3 p(x[0], x[1], x[2]);
    auto [q, face] = tree_.closest_point_and_primitive(p);
    Vec3 qv{q.x(), q.y(), q.z()};
    Vec3 v = x - qv;
    double len = norm(v);
    Plane pl;
    if (len > 1e-12 * (1 + norm(qv))) {
      pl.n = (1.0 / len) * v;
      if ((*inside_)(p) == CGAL::ON_UNBOUNDED_SIDE) pl.n = -1.0 * pl.n;
    } else {
      auto nrm = PMP::compute_face_normal(face, mesh_);  // outward
      pl.n = {-nrm.x(), -nrm.y(), -nrm.z()};
    }
    pl.d = dot(pl.n, qv);
    return pl;
  }
  std::vector<std::string> piece_names() const override { return {"surface"}; }

 private:
  K::Triangle_3 triangle(Mesh::Face_index f) const {
    auto h = mesh_.halfedge(f);
    return {mesh_.point(mesh_.source(h)), mesh_.point(mesh_.target(h)),
            mesh_.point(mesh_.target(mesh_.next(h)))};
  }

  /// Groups coplanar triangles (same inward plane within 1e-9 of the mesh size) into one piece each.
  void group_planes() {
    const double scale = std::max(
        {bounds_.hi[0] - bounds_.lo[0], bounds_.hi[1] - bounds_.lo[1], bounds_.hi[2] - bounds_.lo[2]});
    group_of_.assign(mesh_.number_of_faces(), -1);
    std::map<std::array<long long, 4>, int> index;
    for (auto f : mesh_.faces()) {
      auto nrm = PMP::compute_face_normal(f, mesh_);  // outward, unit
      Plane pl;
      pl.n = {-nrm.x(), -nrm.y(), -nrm.z()};
      const auto& q = mesh_.point(mesh_.target(mesh_.halfedge(f)));
      pl.d = dot(pl.n, Vec3{q.x(), q.y(), q.z()});
      const std::array<long long, 4> key = {std::llround(pl.n[0] * 1e9), std::llround(pl.n[1] * 1e9),
                                            std::llround(pl.n[2] * 1e9), std::llround(pl.d / scale * 1e9)};
      auto [it, fresh] = index.emplace(key, static_cast<int>(planes_.size()));
      if (fresh) planes_.push_back(pl);
      const int found = it->second;
      group_of_[f.idx()] = found;
    }
  }

  Mesh mesh_;
  std::string name_;
  std::vector<Plane> planes_;
  std::vector<int> group_of_;
  mutable std::vector<Mesh::Face_index> hits_;
  Tree tree_;
  std::unique_ptr<Inside> inside_;
  double volume_ = 0;
  Bounds bounds_;
};

}  // namespace

std::unique_ptr<Volume> load_mesh(const std::filesystem::path& file) {
  const std::string name = file.string();
  if (!std::filesystem::exists(file)) throw PackError(fmt::format("{}: no such mesh file", name));
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext != ".off" && ext != ".stl" && ext != ".obj" && ext != ".ply")
    throw PackError(
        fmt::format("{}: unknown mesh format '{}' (expected .off, .stl, .obj or .ply)", name, ext));
  Mesh mesh;
  if (!PMP::IO::read_polygon_mesh(name, mesh) || mesh.number_of_faces() == 0)
    throw PackError(
        fmt::format("{}: cannot read a polygon mesh from it (malformed, empty or non-manifold)", name));
  if (!CGAL::is_triangle_mesh(mesh)) PMP::triangulate_faces(mesh);
  if (!CGAL::is_closed(mesh)) {
    std::size_t border = 0;
    for (auto h : mesh.halfedges())
      if (mesh.is_border(h)) ++border;
    throw PackError(fmt::format(
        "{}: the mesh is open ({} border edges): a volume needs a closed surface (a watertight mesh)", name,
        border));
  }
  if (PMP::does_self_intersect(mesh))
    throw PackError(fmt::format(
        "{}: the mesh intersects itself: a volume needs a surface without self-intersections", name));
  if (!PMP::is_outward_oriented(mesh)) PMP::reverse_face_orientations(mesh);
  if (!(CGAL::to_double(PMP::volume(mesh)) > 0))
    throw PackError(fmt::format("{}: the mesh encloses no volume", name));
  return std::make_unique<MeshVolume>(std::move(mesh), file.filename().string());
}

}  // namespace basalt::packer
