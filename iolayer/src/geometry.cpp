#include "basalt/io/geometry.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "geometry_order.hpp"
#include "id_set.hpp"

namespace basalt::io {

namespace fs = std::filesystem;

FormatError::FormatError(const fs::path& file, const std::string& where, const std::string& what)
    : std::runtime_error(fmt::format("{}{}{}: {}", file.string(), where.empty() ? "" : ": ", where, what)),
      file_(file),
      where_(where) {}

void Geometry::add_particle(std::int64_t pid, const Vec3& pos, double r, std::int32_t ptag) {
  id.push_back(pid);
  position.push_back(pos);
  radius.push_back(r);
  tag.push_back(ptag);
}

void Geometry::sort_by_id() {
  for (auto& b : bonds)
    if (b.a > b.b) std::swap(b.a, b.b);
  if (std::is_sorted(id.begin(), id.end())) return;
  std::vector<std::size_t> order(id.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return id[i] < id[j]; });
  auto permute = [&](auto& v) {
    if (v.empty()) return;
    auto copy = v;
    for (std::size_t k = 0; k < order.size(); ++k) v[k] = copy[order[k]];
  };
  permute(id);
  permute(position);
  permute(radius);
  permute(tag);
  permute(mass);
}

std::int64_t Geometry::index_of(std::int64_t pid) const {
  auto it = std::lower_bound(id.begin(), id.end(), pid);
  if (it == id.end() || *it != pid) return -1;
  return it - id.begin();
}

std::optional<std::pair<std::size_t, std::size_t>> Geometry::duplicate_bond() const {
  using Pair = std::pair<std::int64_t, std::int64_t>;
  auto key = [](const Bond& b) { return b.a < b.b ? Pair{b.a, b.b} : Pair{b.b, b.a}; };
  std::vector<Pair> pairs(bonds.size());
  for (std::size_t k = 0; k < bonds.size(); ++k) pairs[k] = key(bonds[k]);
  std::sort(pairs.begin(), pairs.end());
  const auto twice = std::adjacent_find(pairs.begin(), pairs.end());
  if (twice == pairs.end()) return std::nullopt;
  const Pair p = *twice;
  std::vector<Pair>().swap(pairs);
  std::optional<std::size_t> first;
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    if (key(bonds[k]) != p) continue;
    if (first) return std::pair{*first, k};
    first = k;
  }
  return std::nullopt;  // not reached
}

std::string duplicate_bond_text(const Geometry& g, std::pair<std::size_t, std::size_t> d) {
  const auto& b = g.bonds[d.first];
  return fmt::format(
      "bonds {} and {} (counted from 0 in file order) both join particles {} and {}: a pair bonded twice "
      "acts as "
      "two springs; remove one",
      d.first, d.second, std::min(b.a, b.b), std::max(b.a, b.b));
}

void Geometry::validate(const fs::path& source) const {
  const std::size_t n = id.size();
  if (position.size() != n || radius.size() != n || tag.size() != n)
    throw FormatError(source, "particles",
                      fmt::format("array lengths differ (id {}, position {}, radius {}, tag {})", n,
                                  position.size(), radius.size(), tag.size()));
  if (!mass.empty() && mass.size() != n)
    throw FormatError(source, "particles/mass", fmt::format("{} masses for {} particles", mass.size(), n));
  std::int64_t lo = 0, hi = 0;
  if (n) {
    const auto [mn, mx] = std::minmax_element(id.begin(), id.end());
    lo = *mn;
    hi = *mx;
  }
  IdSet seen(lo, hi, n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!seen.insert(id[i]))
      throw FormatError(source, fmt::format("particle {}", i), fmt::format("duplicate id {}", id[i]));
    const auto& p = position[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw FormatError(source, fmt::format("particle id {}", id[i]), "position is not finite");
    if (!(radius[i] > 0) || !std::isfinite(radius[i]))
      throw FormatError(source, fmt::format("particle id {}", id[i]),
                        fmt::format("radius must be finite and > 0, got {}", radius[i]));
    if (!mass.empty() && (!(mass[i] > 0) || !std::isfinite(mass[i])))
      throw FormatError(source, fmt::format("particle id {}", id[i]),
                        fmt::format("mass must be finite and > 0, got {}", mass[i]));
  }
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    const auto& b = bonds[k];
    if (b.a == b.b)
      throw FormatError(source, fmt::format("bond {}", k), fmt::format("joins particle {} to itself", b.a));
    for (auto e : {b.a, b.b})
      if (!seen.contains(e))
        throw FormatError(source, fmt::format("bond {}", k),
                          fmt::format("refers to particle id {}, which does not exist", e));
  }
  if (const auto d = duplicate_bond()) throw FormatError(source, "bonds", duplicate_bond_text(*this, *d));
}

static std::string lower_extension(const fs::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

GeometryFormat geometry_format(const fs::path& file) {
  const auto ext = lower_extension(file);
  if (ext == ".h5" || ext == ".hdf5") return GeometryFormat::h5;
  if (ext == ".geo") return GeometryFormat::geo;
  throw FormatError(
      file, "",
      fmt::format("unknown geometry format {}: Basalt reads .h5 or .hdf5 (Basalt's HDF5 geometry, "
                  "docs/formats.md; basalt-pack writes it) and .geo (ESyS-Particle's text "
                  "geometry, as GenGeo writes it)",
                  ext.empty() ? std::string("(no extension)") : "'" + ext + "'"));
}

Geometry read_geometry(const fs::path& file) {
  if (geometry_format(file) == GeometryFormat::geo) return read_geo(file);
  return read_h5(file);
}

void write_geometry(const Geometry& g, const fs::path& file) {
  if (geometry_format(file) == GeometryFormat::geo) return write_geo(g, file);
  return write_h5(g, file);
}

std::vector<std::size_t> sorting_order(const std::vector<std::int64_t>& id) {
  if (std::is_sorted(id.begin(), id.end())) return {};
  std::vector<std::size_t> order(id.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return id[i] < id[j]; });
  return order;
}

bool in_file_order(const Geometry& g) {
  return std::is_sorted(g.id.begin(), g.id.end()) &&
         std::all_of(g.bonds.begin(), g.bonds.end(), [](const Bond& b) { return b.a < b.b; });
}

const Geometry& in_file_order(const Geometry& g, Geometry& storage) {
  if (in_file_order(g)) return g;
  storage = g;
  storage.sort_by_id();
  return storage;
}

}  // namespace basalt::io
