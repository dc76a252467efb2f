#pragma once
// Particle state as structure-of-arrays. Owned particles come first (indices [0, n_owned)), ghosts
// (copies of other ranks' particles near this rank's faces) follow. Interactions work on these local
// indices; global ids travel with the particles. Real is the floating-point type of positions,
// velocities and forces (double by default).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace basalt::solver {

template <class Real>
struct Particles {
  std::size_t n_owned = 0;
  // Owned + ghosts:
  std::vector<Real> x, y, z;
  std::vector<Real> radius;
  std::vector<std::int64_t> id;
  std::vector<std::int32_t> tag;
  // Owned only (ghosts need no velocity, force or mass):
  std::vector<Real> vx, vy, vz;
  std::vector<Real> fx, fy, fz;
  std::vector<Real> inv_mass;     ///< 1 / mass (the mass itself is mass(i))
  std::vector<float> x0, y0, z0;  ///< positions at the last neighbour-list rebuild (float: only
                                  ///< compared with half the skin)

  Real mass(std::size_t i) const { return Real(1) / inv_mass[i]; }

  std::size_t size() const { return x.size(); }
  std::size_t n_ghost() const { return x.size() - n_owned; }

  /// Resizes the arrays every particle has (owned + ghosts).
  void resize_all(std::size_t n) {
    x.resize(n);
    y.resize(n);
    z.resize(n);
    radius.resize(n);
    id.resize(n);
    tag.resize(n);
  }
  /// Capacity for n owned particles (exact: no growth slack).
  void reserve_owned(std::size_t n) {
    for (auto* v : {&x, &y, &z, &radius, &vx, &vy, &vz, &fx, &fy, &fz, &inv_mass}) v->reserve(n);
    for (auto* v : {&x0, &y0, &z0}) v->reserve(n);
    id.reserve(n);
    tag.reserve(n);
  }
  /// Resizes the owned-only arrays.
  void resize_owned(std::size_t n) {
    for (auto* v : {&vx, &vy, &vz, &fx, &fy, &fz, &inv_mass}) v->resize(n);
    for (auto* v : {&x0, &y0, &z0}) v->resize(n);
  }
  /// Drops ghosts, keeps owned particles.
  void drop_ghosts() { resize_all(n_owned); }

  /// Appends an owned particle (im = 1 / mass); requires that there are no ghosts.
  void push_owned(std::int64_t gid, Real px, Real py, Real pz, Real r, std::int32_t t, Real im, Real pvx = 0,
                  Real pvy = 0, Real pvz = 0) {
    x.push_back(px);
    y.push_back(py);
    z.push_back(pz);
    radius.push_back(r);
    id.push_back(gid);
    tag.push_back(t);
    vx.push_back(pvx);
    vy.push_back(pvy);
    vz.push_back(pvz);
    fx.push_back(0);
    fy.push_back(0);
    fz.push_back(0);
    inv_mass.push_back(im);
    x0.push_back(float(px));
    y0.push_back(float(py));
    z0.push_back(float(pz));
    ++n_owned;
  }

  /// Reorders the owned particles: new index k holds old index order[k]. Requires no ghosts.
  void permute_owned(const std::vector<std::uint32_t>& order) {
    auto apply = [&](auto& v) {
      auto copy = v;
      for (std::size_t k = 0; k < order.size(); ++k) v[k] = copy[order[k]];
    };
    for (auto* v : {&x, &y, &z, &radius, &vx, &vy, &vz, &fx, &fy, &fz, &inv_mass}) apply(*v);
    for (auto* v : {&x0, &y0, &z0}) apply(*v);
    apply(id);
    apply(tag);
  }

  /// Removes owned particle i by moving the last owned one into its place. Requires no ghosts.
  void swap_remove_owned(std::size_t i) {
    const std::size_t last = n_owned - 1;
    auto mv = [&](auto& v) {
      v[i] = v[last];
      v.pop_back();
    };
    for (auto* v : {&x, &y, &z, &radius, &vx, &vy, &vz, &fx, &fy, &fz, &inv_mass}) mv(*v);
    for (auto* v : {&x0, &y0, &z0}) mv(*v);
    mv(id);
    mv(tag);
    --n_owned;
  }
};

}  // namespace basalt::solver
