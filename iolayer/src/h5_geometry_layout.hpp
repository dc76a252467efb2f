#pragma once
// The geometry part of Basalt's HDF5 schemas (docs/formats.md), shared by "basalt-geometry" and
// "basalt-checkpoint": root attributes for units, box and provenance; /particles, /bonds and
// /statistics. Each schema adds its own identification and, for checkpoints, the run state.
#include <functional>
#include <span>
#include <string>
#include <string_view>

#include "basalt/io/geometry.hpp"
#include "h5_support.hpp"

namespace basalt::io::h5 {

/// Names of root attributes a schema reserves for itself.
using Names = std::span<const std::string_view>;
/// Told the path of each dataset once it is written (a caller that owns the data may free it then).
using Written = std::function<void(std::string_view dataset)>;

/// Writes the `schema`, `schema_version` and `writer` root attributes.
void write_schema(Writer& w, const std::string& schema, int version);
/// Refuses a file whose `schema` differs or whose `schema_version` is newer than `version`
/// (or not a positive integer); `other_hint` is appended when the schema is another Basalt one.
void check_schema(const Reader& r, const std::string& schema, int version);

/// Writes the geometry's root attributes (units, box, periodic, provenance) and the groups
/// /particles, /bonds, /statistics. `g` must be validated, sorted by id, bonds stored a < b.
/// `extra_reserved`: root attributes the calling schema writes itself (provenance may not use them).
/// `written`, when given, hears of /particles/position, radius, tag, mass and /bonds/tag (after
/// which g.bonds is no longer read) as each is written; /particles/id is read to the end.
void write_geometry_layout(Writer& w, const Geometry& g, Names extra_reserved, const Written& written = {});

/// Reads and checks the root attributes write_geometry_layout wrote (units, box, periodic, provenance)
/// into `g`, no particle or bond data.
void read_geometry_attributes(const Reader& r, Names extra_reserved, Geometry& g);

/// The row counts of /particles and /bonds, checked before any row is read: each per-particle dataset
/// (position, radius, tag, mass when present) has one row per id, /bonds/tag one value per pair.
struct LayoutRows {
  std::size_t particles = 0, bonds = 0;
  bool has_mass = false;
};
LayoutRows check_layout_rows(const Reader& r);

/// Reads and checks what write_geometry_layout wrote; every error names the dataset or attribute.
/// Root string attributes that are neither the geometry's nor in `extra_reserved` become provenance.
Geometry read_geometry_layout(const Reader& r, Names extra_reserved);

/// Particle rows [begin, begin + n) of /particles (id, position, radius, tag, and mass when `has_mass`) into
/// `g`, replacing what it held; checked as read_geometry_layout checks them (messages give file rows): ids
/// strictly ascending within these rows, positions finite, radius (and mass) finite and > 0.
void read_particle_rows(const Reader& r, std::size_t begin, std::size_t n, bool has_mass, Geometry& g);
/// Bond rows [begin, begin + m) of /bonds, each checked a != b and a < b.
std::vector<Bond> read_bond_rows(const Reader& r, std::size_t begin, std::size_t m);

}  // namespace basalt::io::h5
