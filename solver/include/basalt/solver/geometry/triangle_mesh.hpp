#pragma once
// A triangle mesh prepared for sphere contact queries: the geometry of mesh walls (silos, hoppers).
// Pure geometry: no MPI, no I/O (io::read_mesh gives the vertices and triangles). docs/mesh-walls.md.
//
// Contacts are found per feature (face interior, edge, vertex) and counted once per touching point of the
// surface: each candidate triangle gives its closest point to the sphere centre and the feature it lies
// on; a face contact always counts; an edge contact counts once, only if no triangle adjacent to the edge
// has its closest point in its interior and the edge point is a local minimum of the distance over the
// triangles adjacent to the edge; a vertex contact counts once, only if no incident triangle gave a face
// contact, no incident edge a contact, and the vertex is a local minimum of the distance over the triangles
// around it. On a flat mesh the contacts a sphere gets therefore sum to exactly one plane contact wherever
// it is; at a convex edge or vertex it gets one contact at the edge or vertex point; in a concave corner
// it gets one contact per face it touches (two or three), as a sphere in a corner of a box should.
//
// Two-sided (default, for open surfaces): a sphere is pushed away from whichever side it is on.
// One-sided (closed meshes wound counter-clockwise seen from the side the particles are on): only
// spheres whose centre is on the side the normals point to touch; a centre behind the surface feels
// nothing (the side of an edge or vertex point is that of its pseudo-normal: the sum of the adjacent
// face normals for an edge, their angle-weighted sum for a vertex).
//
// Moving meshes: set_pose() places the mesh by a rigid transform of its rest vertices (rotation by an
// angle about an axis through a point, then a translation). Queries run in the rest frame (the centre is
// taken there, the contact points and normals brought back), so moving a mesh costs nothing per step and
// its cell grid is built once.
#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace basalt::solver {

/// x -> axis_point + R(axis, angle) (x - axis_point) + translation. The identity by default.
struct RigidTransform {
  std::array<double, 3> translation{0, 0, 0};
  std::array<double, 3> axis_point{0, 0, 0};
  std::array<double, 3> axis{0, 0, 1};  ///< need not be unit length; must be non-zero if angle != 0
  double angle = 0;                     ///< radians, right-handed about axis
};

enum class MeshFeature : std::uint8_t { face, edge, vertex };

/// One contact of a sphere with the mesh (in the world frame, i.e. after the pose).
struct MeshContact {
  std::array<double, 3> point{};   ///< closest point of the mesh feature to the centre
  std::array<double, 3> normal{};  ///< unit, from the mesh towards the sphere centre
  double overlap = 0;              ///< radius - distance (> 0)
  double distance = 0;             ///< |centre - point|
  MeshFeature feature = MeshFeature::face;
  std::int32_t index = -1;     ///< the triangle, edge or vertex (mesh numbering)
  std::int32_t triangle = -1;  ///< a triangle holding the point (the face; else the first adjacent one)
};

class ContactMesh {
 public:
  using Vec3 = std::array<double, 3>;
  using Triangle = std::array<std::int32_t, 3>;
  enum class Sides { two, one };
  struct Options {
    Sides sides = Sides::two;
    double cell_size = 0;  ///< of the candidate grid; 0: the mean longest side of the triangles' boxes
  };

  /// Throws std::invalid_argument for an index out of range, a repeated index or a zero-area triangle.
  ContactMesh(std::vector<Vec3> vertices, std::vector<Triangle> triangles, Options options);
  ContactMesh(std::vector<Vec3> vertices, std::vector<Triangle> triangles)
      : ContactMesh(std::move(vertices), std::move(triangles), Options{}) {}

  // Topology (pose-independent). Edge k of triangle t joins its vertices k and (k+1) % 3.
  std::size_t num_vertices() const { return v_.size(); }
  std::size_t num_triangles() const { return tri_.size(); }
  std::size_t num_edges() const { return edge_v_.size(); }
  const Triangle& triangle(std::size_t t) const { return tri_[t]; }
  const std::array<std::int32_t, 3>& triangle_edges(std::size_t t) const { return tri_edge_[t]; }
  /// The edge's vertices, lower index first.
  const std::array<std::int32_t, 2>& edge(std::size_t e) const { return edge_v_[e]; }
  std::span<const std::int32_t> edge_triangles(std::size_t e) const {
    return csr(edge_tri_off_, edge_tri_, e);
  }
  std::span<const std::int32_t> vertex_triangles(std::size_t v) const {
    return csr(vtx_tri_off_, vtx_tri_, v);
  }
  std::span<const std::int32_t> vertex_edges(std::size_t v) const { return csr(vtx_edge_off_, vtx_edge_, v); }
  std::size_t boundary_edges() const;     ///< edges with one triangle (0 for a closed mesh)
  std::size_t nonmanifold_edges() const;  ///< edges with three or more triangles
  Sides sides() const { return options_.sides; }

  // Geometry.
  const Vec3& rest_vertex(std::size_t v) const { return v_[v]; }
  Vec3 vertex(std::size_t v) const { return to_world(v_[v]); }     ///< after the pose
  Vec3 face_normal(std::size_t t) const { return rotate(n_[t]); }  ///< unit, right-hand rule, after the pose
  /// The rest vertices' bounding box.
  const Vec3& rest_lower() const { return lo_; }
  const Vec3& rest_upper() const { return hi_; }

  void set_pose(const RigidTransform& pose);
  const RigidTransform& pose() const { return pose_; }

  /// Appends the contacts of the sphere (centre, radius) with the mesh to `out`; returns how many.
  std::size_t contacts(const Vec3& centre, double radius, std::vector<MeshContact>& out) const;
  /// The same from every triangle instead of the grid's candidates: the oracle for the grid.
  std::size_t contacts_brute_force(const Vec3& centre, double radius, std::vector<MeshContact>& out) const;
  /// Triangles whose bounding box comes within `reach` of `centre` (per axis), in increasing order.
  void candidates(const Vec3& centre, double reach, std::vector<std::int32_t>& out) const;

 private:
  static std::span<const std::int32_t> csr(const std::vector<std::int32_t>& off,
                                           const std::vector<std::int32_t>& v, std::size_t i) {
    return {v.data() + off[i], static_cast<std::size_t>(off[i + 1] - off[i])};
  }
  Vec3 to_world(const Vec3& x) const;
  Vec3 to_rest(const Vec3& x) const;
  Vec3 rotate(const Vec3& x) const;
  void build_topology();
  void build_grid();
  void rest_candidates(const Vec3& p, double reach, std::vector<std::int32_t>& out) const;
  std::size_t contacts_from(const Vec3& p, double r, const std::vector<std::int32_t>& cand,
                            std::vector<MeshContact>& out) const;

  Options options_;
  std::vector<Vec3> v_;
  std::vector<Triangle> tri_;
  std::vector<std::array<std::int32_t, 3>> tri_edge_;
  std::vector<Vec3> n_;                      ///< unit face normals
  std::vector<std::array<Vec3, 3>> inward_;  ///< per edge of a triangle: unit, in its plane, into it
  std::vector<std::array<Vec3, 2>> box_;     ///< triangle bounding boxes
  std::vector<std::array<std::int32_t, 2>> edge_v_;
  std::vector<Vec3> edge_normal_, vertex_normal_;  ///< pseudo-normals (one-sided meshes)
  std::vector<std::int32_t> edge_tri_off_, edge_tri_, vtx_tri_off_, vtx_tri_, vtx_edge_off_, vtx_edge_;
  Vec3 lo_{}, hi_{};
  double scale_ = 1;  ///< bounding-box diagonal: sets the absolute rounding slack

  // Uniform grid over the triangles' boxes (CSR: cell -> triangles).
  Vec3 grid_lo_{};
  double cell_ = 1;
  std::array<std::int64_t, 3> dims_{1, 1, 1};
  std::vector<std::int64_t> cell_off_;
  std::vector<std::int32_t> cell_tri_;

  RigidTransform pose_;
  bool moved_ = false;
  std::array<std::array<double, 3>, 3> rot_{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
};

}  // namespace basalt::solver
