#include "partition_study.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "basalt/io/geometry.hpp"

namespace basalt::bench {

double ghost_width(double rmax, double longest_bond, bool contacts, double skin) {
  return std::max(contacts ? 2 * rmax : 0.0, longest_bond) + skin;
}

// Same expressions as Decomposition's constructor and coord_of (solver/src/decomposition.cpp), so a
// particle on a cut plane falls on the same side.
std::pair<double, double> region_bounds(int c, int dims, double box_min, double box_max) {
  const double w = (box_max - box_min) / dims;
  const double lo = c == 0 ? -std::numeric_limits<double>::infinity() : box_min + c * w;
  const double hi = c == dims - 1 ? std::numeric_limits<double>::infinity() : box_min + (c + 1) * w;
  return {lo, hi};
}

int region_coord(double v, int dims, double box_min, double box_max) {
  const double w = (box_max - box_min) / dims;
  int c = 0;
  while (c < dims - 1 && v >= box_min + (c + 1) * w) ++c;
  return c;
}

int cart_rank(const std::array<int, 3>& c, const std::array<int, 3>& dims) {
  return (c[0] * dims[1] + c[1]) * dims[2] + c[2];
}

PartitionResult partition(const Cloud& cloud, const std::array<int, 3>& dims, double width,
                          bool keep_ghost_index) {
  for (int d = 0; d < 3; ++d)
    if (dims[d] < 1) throw std::invalid_argument("partition: every grid dimension must be >= 1");
  const int nsub = dims[0] * dims[1] * dims[2];
  PartitionResult res;
  res.dims = dims;
  res.width = width;
  res.sub.resize(static_cast<std::size_t>(nsub));
  std::array<std::vector<double>, 3> lo, hi;
  for (int d = 0; d < 3; ++d)
    for (int c = 0; c < dims[d]; ++c) {
      const auto [l, h] = region_bounds(c, dims[d], cloud.box_min[d], cloud.box_max[d]);
      lo[d].push_back(l);
      hi[d].push_back(h);
    }
  for (int i = 0; i < dims[0]; ++i)
    for (int j = 0; j < dims[1]; ++j)
      for (int k = 0; k < dims[2]; ++k)
        res.sub[static_cast<std::size_t>(cart_rank({i, j, k}, dims))].coords = {i, j, k};

  // Ownership by centre.
  const std::size_t n = cloud.size();
  const std::array<const std::vector<double>*, 3> pos{&cloud.x, &cloud.y, &cloud.z};
  std::vector<std::int32_t> owner(n);
  std::vector<std::vector<std::uint32_t>> held(static_cast<std::size_t>(nsub));
  for (std::size_t p = 0; p < n; ++p) {
    std::array<int, 3> c{};
    for (int d = 0; d < 3; ++d)
      c[d] = region_coord((*pos[d])[p], dims[d], cloud.box_min[d], cloud.box_max[d]);
    owner[p] = cart_rank(c, dims);
    held[static_cast<std::size_t>(owner[p])].push_back(static_cast<std::uint32_t>(p));
  }
  for (int r = 0; r < nsub; ++r)
    res.sub[static_cast<std::size_t>(r)].owned = held[static_cast<std::size_t>(r)].size();

  // Ghost phases, axis after axis (Halo::build_ghosts).
  for (int d = 0; d < 3; ++d) {
    if (dims[d] == 1) continue;
    std::vector<std::vector<std::uint32_t>> incoming(static_cast<std::size_t>(nsub));
    const auto& cd = *pos[d];
    for (int r = 0; r < nsub; ++r) {
      auto& s = res.sub[static_cast<std::size_t>(r)];
      const int c = s.coords[d];
      const bool has_lo = c > 0, has_hi = c < dims[d] - 1;
      s.messages += int(has_lo) + int(has_hi);
      auto nb = s.coords;
      nb[d] = c - 1;
      const int r_lo = has_lo ? cart_rank(nb, dims) : -1;
      nb[d] = c + 1;
      const int r_hi = has_hi ? cart_rank(nb, dims) : -1;
      const double l = lo[d][static_cast<std::size_t>(c)] + width,
                   h = hi[d][static_cast<std::size_t>(c)] - width;
      for (const auto p : held[static_cast<std::size_t>(r)]) {
        const double v = cd[p];
        if (has_lo && v < l) {
          incoming[static_cast<std::size_t>(r_lo)].push_back(p);
          ++s.sent;
        }
        if (has_hi && v >= h) {
          incoming[static_cast<std::size_t>(r_hi)].push_back(p);
          ++s.sent;
        }
      }
    }
    for (int r = 0; r < nsub; ++r) {
      auto& h = held[static_cast<std::size_t>(r)];
      const auto& in = incoming[static_cast<std::size_t>(r)];
      h.insert(h.end(), in.begin(), in.end());
    }
  }
  for (int r = 0; r < nsub; ++r) {
    auto& s = res.sub[static_cast<std::size_t>(r)];
    s.ghosts = held[static_cast<std::size_t>(r)].size() - s.owned;
    if (keep_ghost_index) {
      const auto& h = held[static_cast<std::size_t>(r)];
      std::vector<std::uint32_t> g(h.begin() + static_cast<std::ptrdiff_t>(s.owned), h.end());
      std::sort(g.begin(), g.end());
      res.ghost_index.push_back(std::move(g));
    }
  }
  held.clear();

  // Bonds whose ends are owned by different subdomains (counted once in the total, on both sides per
  // subdomain).
  for (std::uint32_t t = 0; t < cloud.bond_tiles; ++t) {
    const std::uint32_t off = t * cloud.bond_stride;
    for (const auto& [a, b] : cloud.bonds) {
      const int ra = owner[a + off], rb = owner[b + off];
      if (ra == rb) continue;
      ++res.crossing_bonds;
      ++res.sub[static_cast<std::size_t>(ra)].crossing_bonds;
      ++res.sub[static_cast<std::size_t>(rb)].crossing_bonds;
    }
  }
  return res;
}

Cloud load_cloud(const std::string& path) { return cloud_from_geometry(io::read_geometry(path)); }

Cloud cloud_from_geometry(const io::Geometry& g) {
  Cloud c;
  const std::size_t n = g.size();
  c.x.resize(n);
  c.y.resize(n);
  c.z.resize(n);
  c.box_min.fill(std::numeric_limits<double>::infinity());
  c.box_max.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    c.x[i] = g.position[i][0];
    c.y[i] = g.position[i][1];
    c.z[i] = g.position[i][2];
    c.rmax = std::max(c.rmax, g.radius[i]);
    for (int d = 0; d < 3; ++d) {
      c.box_min[d] = std::min(c.box_min[d], g.position[i][d] - g.radius[i]);
      c.box_max[d] = std::max(c.box_max[d], g.position[i][d] + g.radius[i]);
    }
  }
  c.bonds.reserve(g.bonds.size());
  for (const auto& b : g.bonds) {
    const auto ia = static_cast<std::uint32_t>(g.index_of(b.a)),
               ib = static_cast<std::uint32_t>(g.index_of(b.b));
    c.bonds.emplace_back(ia, ib);
    const auto& pa = g.position[ia];
    const auto& pb = g.position[ib];
    c.longest_bond = std::max(c.longest_bond, std::hypot(pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]));
  }
  c.bond_stride = static_cast<std::uint32_t>(n);
  return c;
}

Cloud tile_cloud(const Cloud& base, int n, double side) {
  if (n < 1) throw std::invalid_argument("tile_cloud: n must be >= 1");
  const std::size_t m = base.size(), copies = std::size_t(n) * std::size_t(n) * std::size_t(n);
  if (m * copies > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("tile_cloud: more particles than 32-bit indices hold");
  Cloud c;
  c.rmax = base.rmax;
  c.longest_bond = base.longest_bond;
  c.x.reserve(m * copies);
  c.y.reserve(m * copies);
  c.z.reserve(m * copies);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (std::size_t p = 0; p < m; ++p) {
          c.x.push_back(base.x[p] + i * side);
          c.y.push_back(base.y[p] + j * side);
          c.z.push_back(base.z[p] + k * side);
        }
  for (int d = 0; d < 3; ++d) {
    c.box_min[d] = base.box_min[d];
    c.box_max[d] = base.box_max[d] + (n - 1) * side;
  }
  c.bonds = base.bonds;
  c.bond_tiles = static_cast<std::uint32_t>(copies);
  c.bond_stride = static_cast<std::uint32_t>(m);
  return c;
}

}  // namespace basalt::bench
