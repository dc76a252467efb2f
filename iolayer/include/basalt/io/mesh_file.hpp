#pragma once
// Triangle meshes for mesh walls (silos, hoppers), read from ASCII or binary STL, Wavefront OBJ or OFF
// (docs/mesh-walls.md). The format follows the extension (.stl, .obj, .off, any case); an STL file is
// binary when its size is exactly 84 + 50 n bytes for the n its header gives, ASCII when it
// starts with "solid" and has no control bytes, else a binary STL of the wrong size (an error).
//
// Vertices are welded: coordinates that are exactly equal (-0 equal to +0) become one vertex, so that
// triangles share their edges (STL repeats every vertex per facet); with weld_tolerance > 0, vertices
// closer than weld_tolerance times the diagonal of the mesh's bounding box are merged too (each into the
// first such vertex in file order). Only vertices used by a triangle are kept, in order of first use.
// The winding of each triangle is kept as given (STL, OBJ and OFF all wind counter-clockwise seen from
// outside, so the right-hand normal points outwards).
//
// Degenerate triangles (two equal vertex indices after welding, or an area below 1e-12 times the square
// of its longest edge) are dropped and counted by default; Degenerate::refuse makes them an error.
// Every error is a FormatError naming the file and the line (text formats) or byte offset (binary STL).
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"

namespace basalt::io {

struct TriangleMesh {
  std::vector<Vec3> vertices;
  /// Vertex indices of each triangle, counter-clockwise seen from the side its normal points to.
  std::vector<std::array<std::int32_t, 3>> triangles;

  // What reading did (for the log).
  std::size_t vertices_read = 0;       ///< vertices in the file (STL: 3 per facet)
  std::size_t triangles_read = 0;      ///< triangles after fan triangulation, before dropping
  std::size_t dropped_degenerate = 0;  ///< zero-area triangles dropped
  std::string first_degenerate_where;  ///< "line 12" / "byte offset 184" of the first one dropped

  std::size_t size() const { return triangles.size(); }
};

struct MeshReadOptions {
  enum class Degenerate { drop, refuse };
  Degenerate degenerate = Degenerate::drop;
  /// Merge vertices closer than this times the bounding-box diagonal (0: exactly equal ones only).
  double weld_tolerance = 0;
};

/// Reads a .stl (ASCII or binary), .obj or .off file; throws FormatError (file and line or byte offset)
/// for a missing file, unknown extension, truncated binary STL, bad or non-finite numbers, an index out of
/// range, a face of fewer than 3 vertices, a degenerate triangle (with Degenerate::refuse) or no triangles.
TriangleMesh read_mesh(const std::filesystem::path& file, const MeshReadOptions& options = {});

}  // namespace basalt::io
