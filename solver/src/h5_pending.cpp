// Stand-in until the formats helper's HDF5 geometry reader lands on main (iolayer/src/h5_geometry.cpp):
// .h5 geometries are refused with a clear error, .geo works. Compiled only while that file is missing
// (solver/CMakeLists.txt), so it never clashes with the real reader.
#include <string>

#include "basalt/io/geometry.hpp"

namespace basalt::io {

Geometry read_h5(const std::filesystem::path& file) {
  throw FormatError(file, "", "this build has no HDF5 geometry reader yet; use a .geo file");
}

void write_h5(const Geometry&, const std::filesystem::path& file) {
  throw FormatError(file, "", "this build has no HDF5 geometry writer yet; use a .geo file");
}

}  // namespace basalt::io
