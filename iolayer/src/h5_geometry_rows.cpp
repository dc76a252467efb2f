// Part-wise reading of basalt-geometry files (basalt/io/geometry_rows.hpp): hyperslabs of the datasets
// docs/formats.md describes, checked as read_h5 checks whole files.
#include <fmt/format.h>

#include <cmath>

#include "basalt/io/geometry_rows.hpp"
#include "h5_geometry_layout.hpp"
#include "h5_support.hpp"

namespace basalt::io {

struct GeometryFile::Impl {
  explicit Impl(const std::filesystem::path& f) : r(f) {}
  h5::Reader r;
};

GeometryFile::GeometryFile(const std::filesystem::path& file) : impl_(std::make_unique<Impl>(file)) {
  const auto& r = impl_->r;
  h5::check_schema(r, "basalt-geometry", 1);
  Geometry g;
  h5::read_geometry_attributes(r, {}, g);
  header_.box_min = g.box_min;
  header_.box_max = g.box_max;
  header_.periodic = g.periodic;
  header_.units = g.units;
  header_.attributes = std::move(g.attributes);
  r.require_group("/particles");
  const std::size_t n = r.rows<std::int64_t>("/particles/id");
  auto check_rows = [&](const std::string& ds, std::size_t rows, const char* unit) {
    if (rows != n) r.fail(ds, fmt::format("{} {} for {} particles", rows, unit, n));
  };
  check_rows("/particles/position", r.rows<double>("/particles/position", 3), "rows");
  check_rows("/particles/radius", r.rows<double>("/particles/radius"), "values");
  check_rows("/particles/tag", r.rows<std::int32_t>("/particles/tag"), "values");
  header_.has_mass = r.exists("/particles/mass");
  if (header_.has_mass) check_rows("/particles/mass", r.rows<double>("/particles/mass"), "values");
  header_.particles = n;
  r.require_group("/bonds");
  const std::size_t m = r.rows<std::int64_t>("/bonds/pairs", 2);
  const auto tag_rows = r.rows<std::int32_t>("/bonds/tag");
  if (tag_rows != m) r.fail("/bonds/tag", fmt::format("{} values for {} bonds", tag_rows, m));
  header_.bonds = m;
}

GeometryFile::~GeometryFile() = default;

const std::filesystem::path& GeometryFile::path() const { return impl_->r.file(); }

void GeometryFile::read_particles(std::size_t begin, std::size_t end, Geometry& g) const {
  const auto& r = impl_->r;
  if (begin > end || end > header_.particles)
    throw FormatError(r.file(), "/particles",
                      fmt::format("rows {} to {} asked of {} particles", begin, end, header_.particles));
  const std::size_t n = end - begin;
  g.id.resize(n);
  g.position.resize(n);
  g.radius.resize(n);
  g.tag.resize(n);
  g.mass.resize(header_.has_mass ? n : 0);
  r.read_rows_into("/particles/id", begin, n, 0, g.id.data());
  r.read_rows_into("/particles/position", begin, n, 3, reinterpret_cast<double*>(g.position.data()));
  r.read_rows_into("/particles/radius", begin, n, 0, g.radius.data());
  r.read_rows_into("/particles/tag", begin, n, 0, g.tag.data());
  if (header_.has_mass) r.read_rows_into("/particles/mass", begin, n, 0, g.mass.data());
  for (std::size_t i = 1; i < n; ++i) {
    if (g.id[i] == g.id[i - 1])
      r.fail("/particles/id",
             fmt::format("duplicate id {} (rows {} and {})", g.id[i], begin + i - 1, begin + i));
    if (g.id[i] < g.id[i - 1])
      r.fail("/particles/id", fmt::format("ids must be sorted ascending: id {} at row {} follows id {}",
                                          g.id[i], begin + i, g.id[i - 1]));
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto& p = g.position[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      r.fail("/particles/position",
             fmt::format("particle id {} (row {}): position is not finite", g.id[i], begin + i));
    if (!(g.radius[i] > 0) || !std::isfinite(g.radius[i]))
      r.fail("/particles/radius",
             fmt::format("particle id {} (row {}): radius must be finite and > 0, got {}", g.id[i], begin + i,
                         g.radius[i]));
    if (g.has_mass() && (!(g.mass[i] > 0) || !std::isfinite(g.mass[i])))
      r.fail("/particles/mass", fmt::format("particle id {} (row {}): mass must be finite and > 0, got {}",
                                            g.id[i], begin + i, g.mass[i]));
  }
}

std::vector<Bond> GeometryFile::read_bonds(std::size_t begin, std::size_t end) const {
  const auto& r = impl_->r;
  if (begin > end || end > header_.bonds)
    throw FormatError(r.file(), "/bonds",
                      fmt::format("rows {} to {} asked of {} bonds", begin, end, header_.bonds));
  const std::size_t m = end - begin;
  std::vector<std::int64_t> pairs(2 * m);
  std::vector<std::int32_t> tags(m);
  r.read_rows_into("/bonds/pairs", begin, m, 2, pairs.data());
  r.read_rows_into("/bonds/tag", begin, m, 0, tags.data());
  std::vector<Bond> bonds(m);
  for (std::size_t k = 0; k < m; ++k) {
    const auto a = pairs[2 * k], b = pairs[2 * k + 1];
    if (a == b) r.fail("/bonds/pairs", fmt::format("bond {} joins particle {} to itself", begin + k, a));
    if (a > b)
      r.fail("/bonds/pairs",
             fmt::format("bond {} is ({}, {}): each pair must be stored smaller id first", begin + k, a, b));
    bonds[k] = {a, b, tags[k]};
  }
  return bonds;
}

std::pair<std::size_t, std::size_t> slice_rows(std::size_t n, int part, int parts) {
  const auto p = static_cast<std::size_t>(parts), k = static_cast<std::size_t>(part);
  const std::size_t base = n / p, extra = n % p;
  const std::size_t begin = k * base + std::min(k, extra);
  return {begin, begin + base + (k < extra ? 1 : 0)};
}

}  // namespace basalt::io
