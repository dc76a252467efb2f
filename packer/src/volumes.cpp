// Analytic volumes: box, cylinder (along z), sphere.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "basalt/packer/error.hpp"
#include "basalt/packer/volume.hpp"

namespace basalt::packer {

namespace {

bool finite(const Vec3& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

class BoxVolume final : public Volume {
 public:
  BoxVolume(const Vec3& lo, const Vec3& hi) : lo_(lo), hi_(hi) {
    for (int k = 0; k < 3; ++k) {
      planes_[2 * k].n = {0, 0, 0};
      planes_[2 * k].n[k] = 1;
      planes_[2 * k].d = lo[k];
      planes_[2 * k + 1].n = {0, 0, 0};
      planes_[2 * k + 1].n[k] = -1;
      planes_[2 * k + 1].d = -hi[k];
    }
  }
  std::string description() const override {
    return fmt::format("box {} x {} x {} from ({}, {}, {})", hi_[0] - lo_[0], hi_[1] - lo_[1],
                       hi_[2] - lo_[2], lo_[0], lo_[1], lo_[2]);
  }
  Bounds bounds() const override { return {lo_, hi_}; }
  double measure() const override { return (hi_[0] - lo_[0]) * (hi_[1] - lo_[1]) * (hi_[2] - lo_[2]); }
  double signed_distance(const Vec3& x) const override {
    double d = planes_[0].distance(x);
    for (int k = 1; k < 6; ++k) d = std::min(d, planes_[k].distance(x));
    return d;
  }
  void pieces_near(const Vec3& x, double reach, std::vector<BoundaryPiece>& out) const override {
    for (int k = 0; k < 6; ++k)
      if (planes_[k].distance(x) <= reach) out.push_back({k, true, planes_[k]});
  }
  Plane tangent_plane(int id, const Vec3&) const override { return planes_[id]; }
  std::vector<std::string> piece_names() const override {
    return {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
  }
  bool fills_bounds() const override { return true; }

 private:
  Vec3 lo_, hi_;
  Plane planes_[6];
};

class CylinderVolume final : public Volume {
 public:
  CylinderVolume(const Vec3& base, double radius, double height) : base_(base), r_(radius), h_(height) {
    bottom_.n = {0, 0, 1};
    bottom_.d = base[2];
    top_.n = {0, 0, -1};
    top_.d = -(base[2] + height);
  }
  std::string description() const override {
    return fmt::format("cylinder radius {} height {} along z, base centre ({}, {}, {})", r_, h_, base_[0],
                       base_[1], base_[2]);
  }
  Bounds bounds() const override {
    return {{base_[0] - r_, base_[1] - r_, base_[2]}, {base_[0] + r_, base_[1] + r_, base_[2] + h_}};
  }
  double measure() const override { return std::numbers::pi * r_ * r_ * h_; }
  double signed_distance(const Vec3& x) const override {
    return std::min({side_distance(x), bottom_.distance(x), top_.distance(x)});
  }
  void pieces_near(const Vec3& x, double reach, std::vector<BoundaryPiece>& out) const override {
    if (side_distance(x) <= reach) out.push_back({0, false, tangent_plane(0, x)});
    if (bottom_.distance(x) <= reach) out.push_back({1, true, bottom_});
    if (top_.distance(x) <= reach) out.push_back({2, true, top_});
  }
  Plane tangent_plane(int id, const Vec3& x) const override {
    if (id == 1) return bottom_;
    if (id == 2) return top_;
    double dx = x[0] - base_[0], dy = x[1] - base_[1];
    double rho = std::hypot(dx, dy);
    Plane p;
    p.n = rho > 0 ? Vec3{-dx / rho, -dy / rho, 0} : Vec3{-1, 0, 0};
    // The tangent line touches the circle at base + r * (-n).
    p.d = dot(p.n, base_) - r_;
    return p;
  }
  std::vector<std::string> piece_names() const override { return {"side", "bottom", "top"}; }

 private:
  double side_distance(const Vec3& x) const { return r_ - std::hypot(x[0] - base_[0], x[1] - base_[1]); }
  Vec3 base_;
  double r_, h_;
  Plane bottom_, top_;
};

class SphereVolume final : public Volume {
 public:
  SphereVolume(const Vec3& centre, double radius) : c_(centre), r_(radius) {}
  std::string description() const override {
    return fmt::format("sphere radius {} centred at ({}, {}, {})", r_, c_[0], c_[1], c_[2]);
  }
  Bounds bounds() const override {
    return {{c_[0] - r_, c_[1] - r_, c_[2] - r_}, {c_[0] + r_, c_[1] + r_, c_[2] + r_}};
  }
  double measure() const override { return 4.0 / 3.0 * std::numbers::pi * r_ * r_ * r_; }
  double signed_distance(const Vec3& x) const override { return r_ - norm(x - c_); }
  void pieces_near(const Vec3& x, double reach, std::vector<BoundaryPiece>& out) const override {
    if (signed_distance(x) <= reach) out.push_back({0, false, tangent_plane(0, x)});
  }
  Plane tangent_plane(int, const Vec3& x) const override {
    Vec3 v = x - c_;
    double len = norm(v);
    Plane p;
    p.n = len > 0 ? (-1.0 / len) * v : Vec3{-1, 0, 0};
    p.d = dot(p.n, c_) - r_;
    return p;
  }
  std::vector<std::string> piece_names() const override { return {"surface"}; }

 private:
  Vec3 c_;
  double r_;
};

void require(bool ok, const std::string& what) {
  if (!ok) throw PackError(what);
}

}  // namespace

std::unique_ptr<Volume> make_box(const Vec3& lo, const Vec3& hi) {
  require(finite(lo) && finite(hi), "box: corners must be finite numbers");
  for (int k = 0; k < 3; ++k)
    require(hi[k] > lo[k], fmt::format("box: size must be > 0 in every direction, got {} along {}",
                                       hi[k] - lo[k], "xyz"[k]));
  return std::make_unique<BoxVolume>(lo, hi);
}

std::unique_ptr<Volume> make_cylinder(const Vec3& base_centre, double radius, double height) {
  require(finite(base_centre), "cylinder: base centre must be finite");
  require(radius > 0 && std::isfinite(radius), fmt::format("cylinder: radius must be > 0, got {}", radius));
  require(height > 0 && std::isfinite(height), fmt::format("cylinder: height must be > 0, got {}", height));
  return std::make_unique<CylinderVolume>(base_centre, radius, height);
}

std::unique_ptr<Volume> make_sphere(const Vec3& centre, double radius) {
  require(finite(centre), "sphere: centre must be finite");
  require(radius > 0 && std::isfinite(radius), fmt::format("sphere: radius must be > 0, got {}", radius));
  return std::make_unique<SphereVolume>(centre, radius);
}

}  // namespace basalt::packer
