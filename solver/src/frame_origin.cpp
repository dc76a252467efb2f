#include "basalt/solver/scene/frame_origin.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>

namespace basalt::solver {

Origin frame_origin(const GeometryExtent& e) {
  Origin o{};
  for (std::size_t d = 0; d < 3; ++d) {
    const double c = 0.5 * e.lo[d] + 0.5 * e.hi[d];
    if (std::isfinite(c)) o[d] = c;
  }
  return o;
}

void scene_to_frame(Scene& scene, const Origin& o) {
  const auto shift = [&](std::array<double, 3>& x) {
    for (std::size_t d = 0; d < 3; ++d) x[d] -= o[d];
  };
  for (auto& w : scene.walls) shift(w.point);
  for (auto& m : scene.mesh_walls) {
    for (auto& v : m.vertices) shift(v);
    shift(m.axis_point);
  }
  for (auto& i : scene.inserts) i.region.shift(o);
  for (auto& d : scene.deletes) d.region.shift(o);
  for (auto& f : scene.fields) {
    if (f.type == FieldSpec::Type::runout) shift(f.origin);
    if (f.type == FieldSpec::Type::mass_below || f.type == FieldSpec::Type::mean_vz_above) f.z -= o[2];
  }
}

void geometry_to_frame(io::Geometry& g, const Origin& o) {
  for (auto& x : g.position)
    for (std::size_t d = 0; d < 3; ++d) x[d] -= o[d];
  for (std::size_t d = 0; d < 3; ++d) {
    g.box_min[d] -= o[d];
    g.box_max[d] -= o[d];
  }
}

void extent_to_frame(GeometryExtent& e, const Origin& o) {
  for (std::size_t d = 0; d < 3; ++d) {
    e.lo[d] -= o[d];
    e.hi[d] -= o[d];
  }
}

CheckpointFrame::CheckpointFrame(const io::Checkpoint& c, const Origin& o) : c_(c), o_(o) {
  for (std::size_t k = 0; k < exact_.size(); ++k)
    for (const auto& [name, values] : c.particle_fields)
      if (std::string_view(name) == kFramePositionFields[k] && values.size() == c.size()) exact_[k] = &values;
  // Only whole sets count: the three current positions, the three at the rebuild.
  for (std::size_t s = 0; s < 6; s += 3)
    if (!exact_[s] || !exact_[s + 1] || !exact_[s + 2]) exact_[s] = exact_[s + 1] = exact_[s + 2] = nullptr;
}

io::Vec3 CheckpointFrame::position(std::size_t i, bool at_rebuild) const {
  const std::size_t s = at_rebuild ? 3 : 0;
  if (exact_[s]) return {(*exact_[s])[i], (*exact_[s + 1])[i], (*exact_[s + 2])[i]};
  return point(at_rebuild ? c_.position_at_rebuild[i] : c_.geometry.position[i]);
}

double frame_xmax(const CheckpointFrame& f, std::size_t n) {
  double m = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (const double x : f.position(i, false)) m = std::max(m, std::abs(x));
  return m;
}

}  // namespace basalt::solver
