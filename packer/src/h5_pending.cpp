// Built only while iolayer/ has no HDF5 geometry format yet (see packer/CMakeLists.txt).
#include "basalt/io/geometry.hpp"

namespace basalt::io {

Geometry read_h5(const std::filesystem::path& file) {
  throw FormatError(file, "", "this build has no HDF5 geometry format yet; use .geo");
}
void write_h5(const Geometry&, const std::filesystem::path& file) {
  throw FormatError(file, "", "this build has no HDF5 geometry format yet; use .geo");
}

}  // namespace basalt::io
