// Part-wise reading of basalt-geometry files (basalt/io/geometry_rows.hpp): hyperslabs of the datasets
// docs/formats.md describes, checked as read_h5 checks whole files.
#include <fmt/format.h>

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
  const auto rows = h5::check_layout_rows(r);
  header_.has_mass = rows.has_mass;
  header_.particles = rows.particles;
  header_.bonds = rows.bonds;
}

GeometryFile::~GeometryFile() = default;

const std::filesystem::path& GeometryFile::path() const { return impl_->r.file(); }

void GeometryFile::read_particles(std::size_t begin, std::size_t end, Geometry& g) const {
  const auto& r = impl_->r;
  if (begin > end || end > header_.particles)
    throw FormatError(r.file(), "/particles",
                      fmt::format("rows {} to {} asked of {} particles", begin, end, header_.particles));
  h5::read_particle_rows(r, begin, end - begin, header_.has_mass, g);
}

std::vector<Bond> GeometryFile::read_bonds(std::size_t begin, std::size_t end) const {
  const auto& r = impl_->r;
  if (begin > end || end > header_.bonds)
    throw FormatError(r.file(), "/bonds",
                      fmt::format("rows {} to {} asked of {} bonds", begin, end, header_.bonds));
  return h5::read_bond_rows(r, begin, end - begin);
}

std::pair<std::size_t, std::size_t> slice_rows(std::size_t n, int part, int parts) {
  const auto p = static_cast<std::size_t>(parts), k = static_cast<std::size_t>(part);
  const std::size_t base = n / p, extra = n % p;
  const std::size_t begin = k * base + std::min(k, extra);
  return {begin, begin + base + (k < extra ? 1 : 0)};
}

}  // namespace basalt::io
