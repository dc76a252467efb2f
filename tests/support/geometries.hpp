#pragma once
// Geometries the tests build in memory or read: a hash that jitters them alike on every rank and library,
// grains on a jittered lattice, a cube cut out of a geometry, GenGeo's cube1.geo read once, and a sphere's
// mass.
#include <array>
#include <cstdint>
#include <numbers>

#include "basalt/io/geometry.hpp"
#include "test_support.hpp"

namespace basalt::test {

/// Deterministic value in [-1, 1) from an integer (the same on every rank and every library).
inline double hash_unit(std::uint64_t k) {
  k += 0x9E3779B97F4A7C15ull;
  k = (k ^ (k >> 30)) * 0xBF58476D1CE4E5B9ull;
  k = (k ^ (k >> 27)) * 0x94D049BB133111EBull;
  k ^= k >> 31;
  return double(k >> 11) * 0x1.0p-53 * 2.0 - 1.0;
}

/// Radii 0.35-0.5 by id (the granular columns' grains).
inline double grain_radius(std::uint64_t id) { return 0.425 + 0.075 * hash_unit(id); }

/// The lattice of jittered_lattice: n[0] x n[1] x n[2] sites `spacing` apart from `origin`; each site moved
/// along x and y by `jitter` times hash_unit(3 id + key) and hash_unit(3 id + key + 1).
struct Lattice {
  std::array<int, 3> n{1, 1, 1};
  std::array<double, 3> origin{0.5, 0.5, 0.5};
  double spacing = 1.0;
  double jitter = 0.0;
  std::uint64_t key = 1;
};

/// One grain on each site of `l`, x fastest, ids from 1: grain (i, j, k) has radius radius(id) and tag
/// tag(k).
template <class Radius, class Tag>
io::Geometry jittered_lattice(const Lattice& l, Radius radius, Tag tag) {
  io::Geometry g;
  std::int64_t id = 1;
  for (int k = 0; k < l.n[2]; ++k)
    for (int j = 0; j < l.n[1]; ++j)
      for (int i = 0; i < l.n[0]; ++i, ++id) {
        const auto u = static_cast<std::uint64_t>(id);
        g.add_particle(id,
                       {l.origin[0] + l.spacing * i + l.jitter * hash_unit(3 * u + l.key),
                        l.origin[1] + l.spacing * j + l.jitter * hash_unit(3 * u + l.key + 1),
                        l.origin[2] + l.spacing * k},
                       radius(u), tag(k));
      }
  return g;
}

/// GenGeo's cube1.geo (tests/data, 8,948 bonded particles), read once per process.
inline const io::Geometry& cube1() {
  static const io::Geometry g = io::read_geometry(reference_dir() / "cube1.geo");
  return g;
}

/// The mass of a sphere of radius r and the given density (the solver's default density is 1).
inline double mass_of(double r, double density = 1) {
  return density * 4.0 / 3.0 * std::numbers::pi * r * r * r;
}

/// The particles of `g` inside [lo, hi)^3 and the bonds between them.
inline io::Geometry sub_cube(const io::Geometry& g, double lo, double hi) {
  io::Geometry out;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const auto& x = g.position[i];
    if (x[0] >= lo && x[0] < hi && x[1] >= lo && x[1] < hi && x[2] >= lo && x[2] < hi)
      out.add_particle(g.id[i], x, g.radius[i], g.tag[i]);
  }
  out.sort_by_id();
  for (const auto& b : g.bonds)
    if (out.index_of(b.a) >= 0 && out.index_of(b.b) >= 0) out.bonds.push_back(b);
  return out;
}

}  // namespace basalt::test
