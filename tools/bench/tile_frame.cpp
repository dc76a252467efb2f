// basalt-tile-frame: tiles a geometry n x n x n times into one VTK frame (.vtp), with a synthetic
// velocity field (a vertical wave), to benchmark basalt-view on millions of particles.
//   basalt-tile-frame cube1.geo 5 out.vtp      -> 125 x 8,948 = 1,118,500 particles
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <numbers>

#include "basalt/io/geometry.hpp"
#include "basalt/io/vtk_frames.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    fmt::print(stderr, "usage: {} GEOMETRY N OUT.vtp\n", argv[0]);
    return 2;
  }
  try {
    const basalt::io::Geometry g = basalt::io::read_geometry(argv[1]);
    const int n = std::atoi(argv[2]);
    if (n < 1 || n > 20) throw std::invalid_argument(fmt::format("N = {}: expected 1..20", argv[2]));
    const basalt::io::Vec3 side{g.box_max[0] - g.box_min[0], g.box_max[1] - g.box_min[1],
                                g.box_max[2] - g.box_min[2]};
    basalt::io::Geometry t;
    std::vector<basalt::io::Vec3> velocity;
    const double height = side[2] * n;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const std::int64_t base =
              static_cast<std::int64_t>((k * n + j) * n + i) * static_cast<std::int64_t>(g.size());
          for (std::size_t p = 0; p < g.size(); ++p) {
            const auto& x = g.position[p];
            const basalt::io::Vec3 y{x[0] + i * side[0], x[1] + j * side[1], x[2] + k * side[2]};
            t.add_particle(base + static_cast<std::int64_t>(p), y, g.radius[p], g.tag[p]);
            velocity.push_back({0, 0, 0.1 * std::sin(2 * std::numbers::pi * y[2] / height)});
          }
        }
    basalt::io::ParticleArrays a = basalt::io::arrays_of(t);
    a.velocity = velocity;
    basalt::io::FrameInfo info;
    info.has_clock = true;
    info.step = 1000;
    info.time = 1.0;
    basalt::io::write_vtp(a, info, argv[3]);
    fmt::print("wrote {} ({} particles)\n", argv[3], t.size());
  } catch (const std::exception& e) {
    fmt::print(stderr, "basalt-tile-frame: error: {}\n", e.what());
    return 1;
  }
  return 0;
}
