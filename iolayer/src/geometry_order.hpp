#pragma once
// Every writer stores particles sorted by id and bonds smaller id first. These helpers give the
// writers that order without copying a geometry that already has it.
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "basalt/io/geometry.hpp"

namespace basalt::io {

/// Indices that sort `id` ascending (stable, the order Geometry::sort_by_id() produces), or
/// empty when `id` is already sorted.
std::vector<std::size_t> sorting_order(const std::vector<std::int64_t>& id);

/// True when ids are ascending and every bond is stored a < b.
bool in_file_order(const Geometry& g);

/// The error text for two bonds joining one pair (Geometry::duplicate_bond()).
std::string duplicate_bond_text(const Geometry& g, std::pair<std::size_t, std::size_t> duplicate);

/// `g` itself when in_file_order(g), else a sorted copy kept in `storage`.
const Geometry& in_file_order(const Geometry& g, Geometry& storage);

}  // namespace basalt::io
