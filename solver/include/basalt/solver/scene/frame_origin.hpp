#pragma once
// run.precision = "mixed" (docs/stability.md, "Mixed precision"): the solver holds positions as float
// offsets from a double origin at the centre of the geometry, so that float rounds them to the geometry's
// extent, not to its distance from the coordinate origin. Everything the run compares with positions
// (walls, mesh walls, the decomposition's box and cuts, field savers' heights and origins) lives in the
// same frame; these functions move scenes, geometries and checkpoints into it. Outputs add the origin
// back (frames, checkpoints, wall positions, break positions).
#include <array>
#include <cstddef>
#include <vector>

#include "basalt/io/checkpoint.hpp"
#include "basalt/io/geometry.hpp"
#include "basalt/solver/parallel/geometry_loader.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::solver {

using Origin = std::array<double, 3>;

/// The frame's origin for a geometry of this extent: the centre of its bounding box (zero along an axis
/// where that is not finite).
Origin frame_origin(const GeometryExtent& e);

/// Moves the scene's positions into the frame (subtracts o): planar walls' points, mesh walls' vertices
/// and axis points, the runout savers' origins, the heights of mass_below and mean_vz_above.
void scene_to_frame(Scene& scene, const Origin& o);
/// Subtracts o from the geometry's positions and box.
void geometry_to_frame(io::Geometry& g, const Origin& o);
/// Subtracts o from the extent's box.
void extent_to_frame(GeometryExtent& e, const Origin& o);

/// Names of the particle fields a mixed-precision checkpoint stores its float positions under, exactly
/// (the positions datasets hold origin + position in float64, which cannot hold every float offset
/// exactly): x, y, z, then the positions at the last rebuild.
inline constexpr std::array<const char*, 6> kFramePositionFields{"frame_position_x", "frame_position_y",
                                                                 "frame_position_z", "frame_rebuild_x",
                                                                 "frame_rebuild_y",  "frame_rebuild_z"};

/// A checkpoint's positions in the run's frame (restart): the exact float positions when it stores them
/// (kFramePositionFields), else its absolute positions minus the origin.
class CheckpointFrame {
 public:
  CheckpointFrame(const io::Checkpoint& c, const Origin& o);
  /// Particle i's position (at_rebuild: at the last rebuild, /particles/position_at_rebuild).
  io::Vec3 position(std::size_t i, bool at_rebuild) const;
  /// An absolute point (walls, break positions) in the frame.
  io::Vec3 point(const io::Vec3& x) const { return {x[0] - o_[0], x[1] - o_[1], x[2] - o_[2]}; }

 private:
  const io::Checkpoint& c_;
  Origin o_;
  std::array<const std::vector<double>*, 6> exact_{};  ///< the exact fields, null when absent
};

/// The largest |coordinate| of the checkpoint's n particles in the frame (the load check's xmax).
double frame_xmax(const CheckpointFrame& f, std::size_t n);

}  // namespace basalt::solver
