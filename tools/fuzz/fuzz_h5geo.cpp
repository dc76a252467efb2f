// libFuzzer target: the HDF5 geometry readers on arbitrary bytes (schema basalt-geometry, docs/formats.md):
//  - read_h5 (iolayer/src/h5_geometry.cpp), which basalt-pack, basalt-view and the tests use: the file
//    is refused with a FormatError, or what it returns passes Geometry::validate, has its ids ascending,
//    and survives write_h5 + read_h5 unchanged;
//  - GeometryFile (iolayer/src/h5_geometry_rows.cpp), the sliced reader of basalt-run's start-up (each
//    compute rank reads one slice of the rows, solver/src/geometry_loader.cpp; that routing needs MPI and
//    is not fuzzed here): the header and every slice are read, in 1 to 4 slices by the input's size.
//    Each slice is refused with a FormatError or holds rows that pass the checks the reader documents
//    (ids ascending within the slice, positions finite, radii and masses finite and > 0, bonds a < b).
//    When read_h5 accepts the file, the slices must accept it too and hold exactly read_h5's rows.
// Anything else (a crash, a sanitizer report, another exception, an allocation over libFuzzer's
// -malloc_limit_mb) is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/io/geometry_rows.hpp"
#include "h5_fuzz_file.hpp"

namespace {

using basalt::io::Bond;
using basalt::io::FormatError;
using basalt::io::Geometry;

void require(bool ok) {
  if (!ok) std::abort();
}

// Statistics are any doubles (NaN included): compared bit for bit.
bool same_statistics(const Geometry& a, const Geometry& b) {
  if (a.statistics.size() != b.statistics.size()) return false;
  for (const auto& [name, v] : a.statistics) {
    const auto it = b.statistics.find(name);
    if (it == b.statistics.end() || it->second.size() != v.size() ||
        (!v.empty() && std::memcmp(v.data(), it->second.data(), v.size() * sizeof(double)) != 0))
      return false;
  }
  return true;
}

bool same_rows(const Geometry& a, const Geometry& b) {
  return a.id == b.id && a.position == b.position && a.radius == b.radius && a.tag == b.tag &&
         a.mass == b.mass;
}

// Reads the file slice by slice; nullopt when the header or any slice is refused.
std::optional<Geometry> read_sliced(const std::filesystem::path& file, int parts) {
  try {
    const basalt::io::GeometryFile f(file);
    const auto& h = f.header();
    Geometry all;
    for (int k = 0; k < parts; ++k) {
      const auto [begin, end] = basalt::io::slice_rows(h.particles, k, parts);
      Geometry s;
      f.read_particles(begin, end, s);
      require(s.size() == end - begin && s.position.size() == s.size() && s.radius.size() == s.size() &&
              s.tag.size() == s.size() && s.mass.size() == (h.has_mass ? s.size() : 0));
      for (std::size_t i = 0; i < s.size(); ++i) {
        require(i == 0 || s.id[i - 1] < s.id[i]);
        for (double c : s.position[i]) require(std::isfinite(c));
        require(std::isfinite(s.radius[i]) && s.radius[i] > 0);
        if (h.has_mass) require(std::isfinite(s.mass[i]) && s.mass[i] > 0);
      }
      all.id.insert(all.id.end(), s.id.begin(), s.id.end());
      all.position.insert(all.position.end(), s.position.begin(), s.position.end());
      all.radius.insert(all.radius.end(), s.radius.begin(), s.radius.end());
      all.tag.insert(all.tag.end(), s.tag.begin(), s.tag.end());
      all.mass.insert(all.mass.end(), s.mass.begin(), s.mass.end());
      const auto [bbegin, bend] = basalt::io::slice_rows(h.bonds, k, parts);
      const auto bonds = f.read_bonds(bbegin, bend);
      require(bonds.size() == bend - bbegin);
      for (const Bond& b : bonds) require(b.a < b.b);
      all.bonds.insert(all.bonds.end(), bonds.begin(), bonds.end());
    }
    all.box_min = h.box_min;
    all.box_max = h.box_max;
    all.periodic = h.periodic;
    all.units = h.units;
    all.attributes = h.attributes;
    return all;
  } catch (const FormatError&) {
    return std::nullopt;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto in = basalt::fuzz::h5_scratch("fuzz-h5geo", "in.h5");
  basalt::fuzz::write_input(in, data, size);

  std::optional<Geometry> whole;
  try {
    whole = basalt::io::read_h5(in);
  } catch (const FormatError&) {
  }
  const auto sliced = read_sliced(in, 1 + static_cast<int>(size % 4));
  if (!whole) return 0;

  // Accepted: valid, ids ascending, and the sliced reader agrees row for row.
  const Geometry& g = *whole;
  g.validate(in);
  for (std::size_t i = 1; i < g.size(); ++i) require(g.id[i - 1] < g.id[i]);
  require(sliced.has_value());
  require(same_rows(g, *sliced) && g.bonds == sliced->bonds && g.box_min == sliced->box_min &&
          g.box_max == sliced->box_max && g.periodic == sliced->periodic && g.units == sliced->units &&
          g.attributes == sliced->attributes);

  // And it survives a round trip unchanged.
  const auto out = basalt::fuzz::h5_scratch("fuzz-h5geo", "out.h5");
  basalt::io::write_h5(g, out);
  const auto back = basalt::io::read_h5(out);
  require(same_rows(g, back) && back.bonds == g.bonds && back.box_min == g.box_min &&
          back.box_max == g.box_max && back.periodic == g.periodic && back.units == g.units &&
          back.attributes == g.attributes && same_statistics(g, back));
  return 0;
}
