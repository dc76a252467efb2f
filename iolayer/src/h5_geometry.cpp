// Geometry files in HDF5, schema "basalt-geometry" version 1 (docs/formats.md).
#include "basalt/io/geometry.hpp"
#include "geometry_order.hpp"
#include "h5_geometry_layout.hpp"
#include "h5_support.hpp"

namespace basalt::io {

namespace {
constexpr const char* kSchema = "basalt-geometry";
constexpr int kSchemaVersion = 1;
}  // namespace

Geometry read_h5(const std::filesystem::path& file) {
  return h5::with_memory_guard(file, [&] {
    h5::Reader r(file);
    h5::check_schema(r, kSchema, kSchemaVersion);
    Geometry g = h5::read_geometry_layout(r, {});
    r.close();
    return g;
  });
}

void write_h5(const Geometry& g, const std::filesystem::path& file) {
  g.validate(file);
  Geometry storage;
  const Geometry& s = in_file_order(g, storage);
  h5::Writer w(file, file.string() + ".tmp");
  h5::write_schema(w, kSchema, kSchemaVersion);
  h5::write_geometry_layout(w, s, {});
  w.commit();
}

}  // namespace basalt::io
