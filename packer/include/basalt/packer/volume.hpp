#pragma once
// The region to fill: a box, a cylinder, a sphere or a closed triangle mesh. The packer needs only a
// signed distance (positive inside), the bounding box, the volume, and the boundary near a point as
// planes (exact for flat faces, the tangent plane at the closest point for curved ones).
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "basalt/packer/vec3.hpp"

namespace basalt::packer {

/// Points x with dot(n, x) - d >= 0 are on the inner side; n is a unit vector pointing into the volume.
struct Plane {
  Vec3 n{0, 0, 1};
  double d = 0;
  double distance(const Vec3& x) const { return dot(n, x) - d; }
  Vec3 mirror(const Vec3& x) const { return x - (2 * distance(x)) * n; }
};

/// One face or curved surface of a volume, as seen from a point: its tangent plane there.
struct BoundaryPiece {
  int id = 0;        ///< stable id of the face / surface within the volume
  bool flat = true;  ///< flat pieces have one plane everywhere
  Plane plane;       ///< exact plane (flat) or tangent plane at the point closest to the query
};

struct Bounds {
  Vec3 lo{0, 0, 0};
  Vec3 hi{0, 0, 0};
};

class Volume {
 public:
  virtual ~Volume() = default;
  /// e.g. "box 15 x 15 x 15 at (0, 0, 0)"
  virtual std::string description() const = 0;
  virtual Bounds bounds() const = 0;
  /// Volume in length units cubed.
  virtual double measure() const = 0;
  /// Distance to the boundary, positive inside, negative outside (exact inside; outside only the sign
  /// matters).
  virtual double signed_distance(const Vec3& x) const = 0;
  /// The boundary pieces within distance `reach` of x (x inside), each with its tangent plane.
  virtual void pieces_near(const Vec3& x, double reach, std::vector<BoundaryPiece>& out) const = 0;
  /// Tangent plane of piece `id` at its point closest to x.
  virtual Plane tangent_plane(int id, const Vec3& x) const = 0;
  /// Names of the pieces for region tags: e.g. {"xmin", ...}; "surface" always means every piece.
  virtual std::vector<std::string> piece_names() const = 0;
  /// True when the volume is its bounding box (an axis-aligned box): the packer can then split it into
  /// tiles whose volumes are known exactly and pack them in parallel (docs/packer.md, "Tiles").
  virtual bool fills_bounds() const { return false; }
};

/// Axis-aligned box [lo, hi]. Faces: 0 xmin, 1 xmax, 2 ymin, 3 ymax, 4 zmin, 5 zmax.
std::unique_ptr<Volume> make_box(const Vec3& lo, const Vec3& hi);
/// Cylinder along z: base centre, radius, height. Pieces: 0 side, 1 bottom (zmin), 2 top (zmax).
std::unique_ptr<Volume> make_cylinder(const Vec3& base_centre, double radius, double height);
/// Ball. Piece 0: its surface.
std::unique_ptr<Volume> make_sphere(const Vec3& centre, double radius);
/// Closed, non-self-intersecting triangle mesh read by CGAL (OFF, STL, OBJ, PLY). Throws PackError
/// naming the file when it cannot be read, is open, or intersects itself. Piece 0: its surface.
std::unique_ptr<Volume> load_mesh(const std::filesystem::path& file);

}  // namespace basalt::packer
