#include "h5_geometry_layout.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "basalt/version.hpp"
#include "geometry_order.hpp"
#include "id_set.hpp"

namespace basalt::io::h5 {

namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 must be three packed doubles");

// Root attributes the geometry layout (and write_schema) owns; provenance may not use them.
constexpr std::string_view kGeometryReserved[] = {"schema",    "schema_version", "writer",    "length_unit",
                                                  "time_unit", "force_unit",     "mass_unit", "box_min",
                                                  "box_max",   "periodic"};

bool reserved(std::string_view name, Names extra) {
  return std::find(std::begin(kGeometryReserved), std::end(kGeometryReserved), name) !=
             std::end(kGeometryReserved) ||
         std::find(extra.begin(), extra.end(), name) != extra.end();
}

std::string root_attribute(const std::string& name) { return fmt::format("attribute '{}' of /", name); }

// An HDF5 link or attribute name Basalt can write and h5py can address.
void check_name(const Writer& w, const std::string& where, const std::string& name) {
  if (name.empty() || name == "." || name.find('/') != std::string::npos)
    w.fail(where, fmt::format("name '{}' is not usable in HDF5 (empty, '.' or contains '/')", name));
}

}  // namespace

void write_schema(Writer& w, const std::string& schema, int version) {
  w.attribute("/", "schema", schema);
  w.scalar_attribute<std::int32_t>("/", "schema_version", version);
  w.attribute("/", "writer", fmt::format("basalt {}", basalt::kVersion));
}

void check_schema(const Reader& r, const std::string& schema, int version) {
  if (!r.has_attribute("/", "schema"))
    r.fail(root_attribute("schema"),
           fmt::format("missing: not a Basalt file (expected schema '{}')", schema));
  const auto found = r.string_attribute("/", "schema");
  if (found != schema) {
    std::string hint;
    if (found == "basalt-checkpoint") hint = " (this is a checkpoint: read it with read_checkpoint)";
    if (found == "basalt-geometry") hint = " (this is a geometry file, not a checkpoint)";
    r.fail(root_attribute("schema"), fmt::format("is '{}', expected '{}'{}", found, schema, hint));
  }
  const auto v = r.scalar_attribute<std::int64_t>("/", "schema_version");
  if (v > version)
    r.fail(root_attribute("schema_version"),
           fmt::format("{} version {} is newer than this Basalt ({}) reads (up to {}): use a newer Basalt",
                       schema, v, basalt::kVersion, version));
  if (v < 1) r.fail(root_attribute("schema_version"), fmt::format("must be >= 1, found {}", v));
}

void write_geometry_layout(Writer& w, const Geometry& g, Names extra_reserved, const Written& written) {
  w.attribute("/", "length_unit", g.units.length);
  w.attribute("/", "time_unit", g.units.time);
  w.attribute("/", "force_unit", g.units.force);
  w.attribute("/", "mass_unit", g.units.mass);
  w.attribute("/", "box_min", g.box_min.data(), 3);
  w.attribute("/", "box_max", g.box_max.data(), 3);
  const std::uint8_t periodic[3] = {g.periodic[0], g.periodic[1], g.periodic[2]};
  w.attribute("/", "periodic", periodic, 3);
  for (const auto& [name, value] : g.attributes) {
    check_name(w, root_attribute(name), name);
    if (reserved(name, extra_reserved))
      w.fail(root_attribute(name), "this provenance entry uses a name the schema reserves; rename it");
    w.attribute("/", name, value);
  }

  const auto done = [&](std::string_view dataset) {
    if (written) written(dataset);
  };
  const std::size_t n = g.size();
  w.group("/particles");
  w.dataset("/particles/id", g.id);
  w.dataset("/particles/position", reinterpret_cast<const double*>(g.position.data()), n, 3);
  done("/particles/position");
  w.dataset("/particles/radius", g.radius);
  done("/particles/radius");
  w.dataset("/particles/tag", g.tag);
  done("/particles/tag");
  if (g.has_mass()) {
    w.dataset("/particles/mass", g.mass);
    done("/particles/mass");
  }

  // One bond column at a time (the pairs, then the tags), each freed once written.
  const std::size_t m = g.bonds.size();
  w.group("/bonds");
  {
    std::vector<std::int64_t> pairs(2 * m);
    for (std::size_t k = 0; k < m; ++k) {
      pairs[2 * k] = g.bonds[k].a;
      pairs[2 * k + 1] = g.bonds[k].b;
    }
    w.dataset("/bonds/pairs", pairs.data(), m, 2);
  }
  {
    std::vector<std::int32_t> tags(m);
    for (std::size_t k = 0; k < m; ++k) tags[k] = g.bonds[k].tag;
    w.dataset("/bonds/tag", tags);
  }
  done("/bonds/tag");

  w.group("/statistics");
  for (const auto& [name, values] : g.statistics) {
    check_name(w, "/statistics/" + name, name);
    w.dataset("/statistics/" + name, values);
  }
}

void read_geometry_attributes(const Reader& r, Names extra_reserved, Geometry& g) {
  g.units.length = r.string_attribute("/", "length_unit");
  g.units.time = r.string_attribute("/", "time_unit");
  g.units.force = r.string_attribute("/", "force_unit");
  g.units.mass = r.string_attribute("/", "mass_unit");

  const auto lo = r.numeric_attribute<double>("/", "box_min", 3);
  const auto hi = r.numeric_attribute<double>("/", "box_max", 3);
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(lo[k]) || !std::isfinite(hi[k]) || lo[k] > hi[k])
      r.fail(root_attribute("box_max"),
             fmt::format("box_min {} and box_max {} must be finite with box_min <= box_max (axis {})", lo[k],
                         hi[k], "xyz"[k]));
    g.box_min[k] = lo[k];
    g.box_max[k] = hi[k];
  }
  const auto periodic = r.numeric_attribute<std::int64_t>("/", "periodic", 3);
  for (int k = 0; k < 3; ++k) {
    if (periodic[k] != 0 && periodic[k] != 1)
      r.fail(root_attribute("periodic"), fmt::format("flags must be 0 or 1, found {}", periodic[k]));
    g.periodic[k] = periodic[k] == 1;
  }
  for (const auto& name : r.attribute_names("/")) {
    if (reserved(name, extra_reserved)) continue;
    if (!r.attribute_is_string("/", name))
      r.fail(root_attribute(name), "provenance attributes must be strings");
    g.attributes[name] = r.string_attribute("/", name);
  }
}

LayoutRows check_layout_rows(const Reader& r) {
  LayoutRows rows;
  r.require_group("/particles");
  const std::size_t n = rows.particles = r.rows<std::int64_t>("/particles/id");
  auto check_rows = [&](const std::string& ds, std::size_t found, const char* unit) {
    if (found != n) r.fail(ds, fmt::format("{} {} for {} particles", found, unit, n));
  };
  check_rows("/particles/position", r.rows<double>("/particles/position", 3), "rows");
  check_rows("/particles/radius", r.rows<double>("/particles/radius"), "values");
  check_rows("/particles/tag", r.rows<std::int32_t>("/particles/tag"), "values");
  rows.has_mass = r.exists("/particles/mass");
  if (rows.has_mass) check_rows("/particles/mass", r.rows<double>("/particles/mass"), "values");
  r.require_group("/bonds");
  const std::size_t m = rows.bonds = r.rows<std::int64_t>("/bonds/pairs", 2);
  const auto tag_rows = r.rows<std::int32_t>("/bonds/tag");
  if (tag_rows != m) r.fail("/bonds/tag", fmt::format("{} values for {} bonds", tag_rows, m));
  return rows;
}

Geometry read_geometry_layout(const Reader& r, Names extra_reserved) {
  Geometry g;
  read_geometry_attributes(r, extra_reserved, g);

  // Particles: every per-particle dataset has one row per id.
  const auto rows = check_layout_rows(r);
  const std::size_t n = rows.particles;
  g.id = r.read<std::int64_t>("/particles/id");
  g.position.resize(n);
  if (n) r.read_into("/particles/position", reinterpret_cast<double*>(g.position.data()));
  g.radius = r.read<double>("/particles/radius");
  g.tag = r.read<std::int32_t>("/particles/tag");
  if (rows.has_mass) g.mass = r.read<double>("/particles/mass");

  for (std::size_t i = 1; i < n; ++i) {
    if (g.id[i] == g.id[i - 1])
      r.fail("/particles/id", fmt::format("duplicate id {} (rows {} and {})", g.id[i], i - 1, i));
    if (g.id[i] < g.id[i - 1])
      r.fail("/particles/id", fmt::format("ids must be sorted ascending: id {} at row {} follows id {}",
                                          g.id[i], i, g.id[i - 1]));
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto& p = g.position[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      r.fail("/particles/position",
             fmt::format("particle id {} (row {}): position is not finite", g.id[i], i));
    if (!(g.radius[i] > 0) || !std::isfinite(g.radius[i]))
      r.fail("/particles/radius",
             fmt::format("particle id {} (row {}): radius must be finite and > 0, got {}", g.id[i], i,
                         g.radius[i]));
    if (g.has_mass() && (!(g.mass[i] > 0) || !std::isfinite(g.mass[i])))
      r.fail("/particles/mass", fmt::format("particle id {} (row {}): mass must be finite and > 0, got {}",
                                            g.id[i], i, g.mass[i]));
  }

  // Bonds: pairs of existing ids, smaller id first.
  const auto pairs = r.read<std::int64_t>("/bonds/pairs", 2);
  const std::size_t m = rows.bonds;
  const auto tags = r.read<std::int32_t>("/bonds/tag");
  IdSet ids(n ? g.id.front() : 0, n ? g.id.back() : 0, n);
  for (auto pid : g.id) ids.insert(pid);
  g.bonds.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    const auto a = pairs[2 * k];
    const auto b = pairs[2 * k + 1];
    if (a == b) r.fail("/bonds/pairs", fmt::format("bond {} joins particle {} to itself", k, a));
    if (a > b)
      r.fail("/bonds/pairs",
             fmt::format("bond {} is ({}, {}): each pair must be stored smaller id first", k, a, b));
    for (auto e : {a, b})
      if (!ids.contains(e))
        r.fail("/bonds/pairs", fmt::format("bond {} refers to particle id {}, which does not exist", k, e));
    g.bonds[k] = {a, b, tags[k]};
  }
  if (const auto d = g.duplicate_bond()) r.fail("/bonds/pairs", duplicate_bond_text(g, *d));

  // Statistics are optional: files written by other tools may leave them out.
  if (r.exists("/statistics"))
    for (const auto& name : r.members("/statistics"))
      g.statistics[name] = r.read<double>("/statistics/" + name);

  // Every invariant of Geometry::validate() has been checked above, naming the dataset.
  return g;
}

void read_particle_rows(const Reader& r, std::size_t begin, std::size_t n, bool has_mass, Geometry& g) {
  g.id.resize(n);
  g.position.resize(n);
  g.radius.resize(n);
  g.tag.resize(n);
  g.mass.resize(has_mass ? n : 0);
  r.read_rows_into("/particles/id", begin, n, 0, g.id.data());
  r.read_rows_into("/particles/position", begin, n, 3, reinterpret_cast<double*>(g.position.data()));
  r.read_rows_into("/particles/radius", begin, n, 0, g.radius.data());
  r.read_rows_into("/particles/tag", begin, n, 0, g.tag.data());
  if (has_mass) r.read_rows_into("/particles/mass", begin, n, 0, g.mass.data());
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

std::vector<Bond> read_bond_rows(const Reader& r, std::size_t begin, std::size_t m) {
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

}  // namespace basalt::io::h5
