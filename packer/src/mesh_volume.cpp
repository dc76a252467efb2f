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
#include <cmath>

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
  void pieces_near(const Vec3& x, double reach, std::vector<BoundaryPiece>& out) const override {
    K::Point_3 p(x[0], x[1], x[2]);
    if (tree_.squared_distance(p) <= reach * reach) out.push_back({0, false, tangent_plane(0, x)});
  }
  Plane tangent_plane(int, const Vec3& x) const override {
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
  Mesh mesh_;
  std::string name_;
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
