#pragma once
// The scene's planar walls as the run moves them: each wall's point at the current time, the force
// the particles put on it (this rank's share, summed by whichever wall models act on it), and the
// owned particles within reach of it since the last rebuild. Wall models (wall_driver.hpp) read
// and write these; field savers, frames and the energy guard read them.
// The scene's mesh walls likewise (mesh_wall_driver.hpp): each mesh's ContactMesh at its pose at the
// current time, its force and power, and its candidates (owned particles within radius + skin of a
// triangle's box at the rebuild). A moving mesh counts in moved2_since_rebuild() by the largest
// displacement of its vertices since the rebuild (exact for a rigid motion: the displacement is affine
// in the point, so its largest norm over a triangle is at a vertex); with the particles' own
// displacements limited the same way, no particle outside the candidates can reach the mesh before the
// next rebuild.
#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/geometry/triangle_mesh.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::solver {

class Walls {
 public:
  explicit Walls(const std::vector<WallSpec>& walls, const std::vector<MeshWallSpec>& meshes = {})
      : walls_(walls), point_(walls.size()), force_(walls.size()), velocity_(walls.size()) {
    for (std::size_t w = 0; w < walls.size(); ++w) {
      point_[w] = walls[w].point;
      if (walls[w].removed) remove(w);
    }
    for (const auto& m : meshes) {
      ContactMesh::Options opt;
      opt.sides = m.one_sided ? ContactMesh::Sides::one : ContactMesh::Sides::two;
      meshes_.emplace_back(m, ContactMesh(m.vertices, m.triangles, opt));
    }
  }

  /// No planar and no mesh walls.
  bool empty() const { return walls_.empty() && meshes_.empty(); }
  std::size_t size() const { return walls_.size(); }
  const WallSpec& spec(std::size_t w) const { return walls_[w]; }
  const std::array<double, 3>& point(std::size_t w) const { return point_[w]; }
  /// Force the particles put on wall w at the last force computation (this rank's share).
  const std::array<double, 3>& force(std::size_t w) const { return force_[w]; }
  std::array<double, 3>& force(std::size_t w) { return force_[w]; }
  /// Owned particles within reach of wall w (local indices), from the last rebuild.
  const std::vector<std::int32_t>& candidates(std::size_t w) const { return candidates_[w]; }

  /// Velocity of wall w at the time of the last move_to().
  const std::array<double, 3>& velocity(std::size_t w) const { return velocity_[w]; }

  // Mesh walls (the history id of mesh k is -1 - (size() + k)).
  std::size_t meshes() const { return meshes_.size(); }
  const MeshWallSpec& mesh_spec(std::size_t k) const { return meshes_[k].spec; }
  const ContactMesh& mesh(std::size_t k) const { return meshes_[k].mesh; }
  const std::vector<std::int32_t>& mesh_candidates(std::size_t k) const { return meshes_[k].candidates; }
  /// Force the particles put on mesh k at the last force computation (this rank's share).
  const std::array<double, 3>& mesh_force(std::size_t k) const { return meshes_[k].force; }
  std::array<double, 3>& mesh_force(std::size_t k) { return meshes_[k].force; }
  /// Power mesh k put into the particles at the last force computation: sum of F . v_wall(contact point).
  double& mesh_power(std::size_t k) { return meshes_[k].power; }
  /// Translation velocity of mesh k at the last move_to().
  const std::array<double, 3>& mesh_velocity(std::size_t k) const { return meshes_[k].velocity; }
  /// Where its rotation axis passes now (the axis point carried by the translation).
  const std::array<double, 3>& mesh_axis_point(std::size_t k) const { return meshes_[k].axis_point; }
  /// Velocity of mesh k's material point q at the last move_to(): v + omega x (q - axis point).
  std::array<double, 3> mesh_velocity_at(std::size_t k, const std::array<double, 3>& q) const {
    const auto& m = meshes_[k];
    const auto& a = m.spec.axis;
    const double w = m.spec.angular_velocity;
    const double rx = q[0] - m.axis_point[0], ry = q[1] - m.axis_point[1], rz = q[2] - m.axis_point[2];
    return {m.velocity[0] + w * (a[1] * rz - a[2] * ry), m.velocity[1] + w * (a[2] * rx - a[0] * rz),
            m.velocity[2] + w * (a[0] * ry - a[1] * rx)};
  }

  /// Servo walls (motion type servo) have no closed form: their point and velocity are state, moved
  /// by advance_servos() and steered by steer_servo(); move_to() leaves them where they are.
  bool servo(std::size_t w) const { return walls_[w].motion.type == WallMotion::Type::servo; }
  bool has_servo() const {
    for (std::size_t w = 0; w < walls_.size(); ++w)
      if (servo(w)) return true;
    return false;
  }
  /// Moves each servo wall by its velocity over dt (a step's motion, before its forces).
  void advance_servos(double dt) {
    for (std::size_t w = 0; w < walls_.size(); ++w)
      if (servo(w))
        for (int d = 0; d < 3; ++d) point_[w][d] += velocity_[w][d] * dt;
  }
  /// Sets servo wall w's velocity for the next step from the force all the particles (every rank's
  /// share summed) put on it now.
  void steer_servo(std::size_t w, const std::array<double, 3>& total_force) {
    const auto& n = walls_[w].normal;
    const double fn = -(total_force[0] * n[0] + total_force[1] * n[1] + total_force[2] * n[2]);
    const double v = walls_[w].motion.servo.speed(fn);
    velocity_[w] = {v * n[0], v * n[1], v * n[2]};
  }
  /// Where wall w was at the last rebuild (a servo wall's restart state).
  std::array<double, 3> point_at_rebuild(std::size_t w) const {
    return w < point_at_rebuild_.size() ? point_at_rebuild_[w] : point_[w];
  }
  /// Restart: a servo wall's state as a checkpoint holds it.
  void restore_servo(std::size_t w, const std::array<double, 3>& point,
                     const std::array<double, 3>& velocity) {
    point_[w] = point;
    velocity_[w] = velocity;
  }

  /// Moves the walls to their positions at time t.
  void move_to(double t) {
    velocity_.resize(walls_.size());
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      if (servo(w)) continue;
      const auto u = walls_[w].motion.displacement_at(t);
      for (int d = 0; d < 3; ++d) point_[w][d] = walls_[w].point[d] + u[d];
      velocity_[w] = walls_[w].motion.velocity_at(t);
    }
    for (auto& m : meshes_) {
      if (!m.spec.moves()) continue;  // the identity pose: rest-frame results, bit for bit
      RigidTransform pose;
      pose.translation = m.spec.motion.displacement_at(t);
      pose.axis_point = m.spec.axis_point;
      pose.axis = m.spec.axis;
      pose.angle = m.spec.angular_velocity * t;
      m.mesh.set_pose(pose);
      m.velocity = m.spec.motion.velocity_at(t);
      for (int d = 0; d < 3; ++d) m.axis_point[d] = m.spec.axis_point[d] + pose.translation[d];
    }
  }

  /// Power the walls put into the particles over the step that ended at the last move_to() (this
  /// rank's share): -F_wall . v_wall (a servo wall's velocity of that step: call before steer_servo()).
  double power() const {
    double pw = 0;
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const auto& v = velocity_[w];
      pw -= force_[w][0] * v[0] + force_[w][1] * v[1] + force_[w][2] * v[2];
    }
    for (const auto& m : meshes_) pw += m.power;
    return pw;
  }

  /// From time t on, wall w moves at the constant velocity v from where it is (a wall steered between steps,
  /// e.g. from Python; a servo wall stops being one). The next move_to() continues from its point now.
  void set_velocity(std::size_t w, const std::array<double, 3>& v, double t) {
    auto& m = walls_[w].motion;
    m = WallMotion{};
    m.type = WallMotion::Type::ramp;  // a step to v at t: u(t') = v (t' - t)
    m.velocity = v;
    m.start_time = t;
    walls_[w].point = point_[w];
  }
  /// From time t on, wall w moves by m from where it is, m's clock starting at t (a servo wall starts at rest
  /// and steers itself from the next step's force).
  void set_motion(std::size_t w, WallMotion m, double t) {
    m.origin_time = t;
    walls_[w].motion = m;
    walls_[w].point = point_[w];
    velocity_[w] = servo(w) ? std::array<double, 3>{0, 0, 0} : m.velocity_at(t);
  }
  /// Shifts wall w by u now, with the anchor of its motion (ESyS's moveWallBy: its motion goes on from
  /// there).
  void shift(std::size_t w, const std::array<double, 3>& u) {
    for (int d = 0; d < 3; ++d) {
      walls_[w].point[d] += u[d];
      point_[w][d] += u[d];
    }
  }
  /// Wall w touches no particle from the next rebuild on (a gate taken away); it keeps its place and motion.
  void remove(std::size_t w) {
    removed_.resize(walls_.size(), 0);
    removed_[w] = 1;
  }
  /// Wall w touches particles again from the next rebuild on (a wall added, a gate put back).
  void restore(std::size_t w) {
    if (w < removed_.size()) removed_[w] = 0;
  }
  bool removed(std::size_t w) const { return w < removed_.size() && removed_[w]; }

  /// The signed distance of point x from wall w's plane now (positive on the particles' side).
  double distance(std::size_t w, double x, double y, double z) const {
    const auto& n = walls_[w].normal;
    return (x - point_[w][0]) * n[0] + (y - point_[w][1]) * n[1] + (z - point_[w][2]) * n[2];
  }
  /// Whether wall w touches particles of this tag (its tags, or all when it names none).
  bool touches_tag(std::size_t w, std::int64_t tag) const {
    const auto& tags = walls_[w].tags;
    return tags.empty() || std::find(tags.begin(), tags.end(), tag) != tags.end();
  }

  /// At a rebuild: the owned particles within reach of each wall (centre closer than radius + skin,
  /// taking the wall's tags), so that steps loop over those only.
  template <class Real>
  void rebuild(const Particles<Real>& p, double skin) {
    candidates_.resize(walls_.size());
    point_at_rebuild_ = point_;
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const auto& spec = walls_[w];
      auto& c = candidates_[w];
      c.clear();
      if (removed(w)) continue;
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        if (!spec.bond_tags.empty() && spec.bonds(p.tag[i])) {  // tied to the wall wherever it is
          c.push_back(static_cast<std::int32_t>(i));
          continue;
        }
        if (distance(w, p.x[i], p.y[i], p.z[i]) >= double(p.radius[i]) + skin) continue;
        if (!touches_tag(w, p.tag[i])) continue;
        c.push_back(static_cast<std::int32_t>(i));
      }
    }
    thread_local std::vector<std::int32_t> tris;
    for (auto& m : meshes_) {
      auto& c = m.candidates;
      c.clear();
      const auto& tags = m.spec.tags;
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        if (!tags.empty() && std::find(tags.begin(), tags.end(), p.tag[i]) == tags.end()) continue;
        tris.clear();
        m.mesh.candidates({double(p.x[i]), double(p.y[i]), double(p.z[i])}, double(p.radius[i]) + skin, tris);
        if (!tris.empty()) c.push_back(static_cast<std::int32_t>(i));
      }
      if (m.spec.moves()) {
        m.vertices_at_rebuild.resize(m.mesh.num_vertices());
        for (std::size_t v = 0; v < m.vertices_at_rebuild.size(); ++v)
          m.vertices_at_rebuild[v] = m.mesh.vertex(v);
      }
    }
  }

  /// Squared distance the walls moved towards their particles since the last rebuild (the same on
  /// every rank): with particle displacements, it decides the next rebuild.
  double moved2_since_rebuild() const {
    double m = 0;
    for (std::size_t w = 0; w < walls_.size() && w < point_at_rebuild_.size(); ++w) {
      const auto& n = walls_[w].normal;
      const double u = (point_[w][0] - point_at_rebuild_[w][0]) * n[0] +
                       (point_[w][1] - point_at_rebuild_[w][1]) * n[1] +
                       (point_[w][2] - point_at_rebuild_[w][2]) * n[2];
      if (u > 0) m = std::max(m, u * u);
    }
    for (const auto& mw : meshes_) {
      if (!mw.spec.moves()) continue;
      for (std::size_t v = 0; v < mw.vertices_at_rebuild.size(); ++v) {
        const auto x = mw.mesh.vertex(v);
        const auto& x0 = mw.vertices_at_rebuild[v];
        m = std::max(m, (x[0] - x0[0]) * (x[0] - x0[0]) + (x[1] - x0[1]) * (x[1] - x0[1]) +
                            (x[2] - x0[2]) * (x[2] - x0[2]));
      }
    }
    return m;
  }

  std::size_t memory_bytes() const {
    std::size_t b = 0;
    for (const auto& c : candidates_) b += c.capacity() * sizeof(std::int32_t);
    for (const auto& m : meshes_) b += m.candidates.capacity() * sizeof(std::int32_t);
    return b;
  }

 private:
  std::vector<WallSpec> walls_;
  std::vector<std::array<double, 3>> point_;
  std::vector<std::array<double, 3>> force_;
  std::vector<std::array<double, 3>> velocity_;
  std::vector<std::array<double, 3>> point_at_rebuild_;
  std::vector<std::vector<std::int32_t>> candidates_;
  std::vector<char> removed_;  ///< remove(): no candidates from the next rebuild on

  struct Mesh {
    Mesh(const MeshWallSpec& s, ContactMesh m) : spec(s), mesh(std::move(m)), axis_point(s.axis_point) {}
    MeshWallSpec spec;
    ContactMesh mesh;
    std::vector<std::int32_t> candidates;
    std::array<double, 3> force{0, 0, 0};
    double power = 0;
    std::array<double, 3> velocity{0, 0, 0};
    std::array<double, 3> axis_point;
    std::vector<std::array<double, 3>> vertices_at_rebuild;  ///< moving meshes only
  };
  std::vector<Mesh> meshes_;
};

}  // namespace basalt::solver
