#pragma once
// Helpers shared by Basalt's tests: where the data are, scratch folders, the MPI world.
#include <mpi.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace basalt::test {

/// The communicator tests run on (the whole job; tests have no I/O ranks unless they split it).
inline MPI_Comm world() { return MPI_COMM_WORLD; }

inline int rank() {
  int r = 0;
  MPI_Comm_rank(world(), &r);
  return r;
}

inline int size() {
  int s = 1;
  MPI_Comm_size(world(), &s);
  return s;
}

/// The source tree (set by CTest through BASALT_SOURCE_DIR).
inline std::filesystem::path source_dir() {
  const char* s = std::getenv("BASALT_SOURCE_DIR");
  return s ? std::filesystem::path(s) : std::filesystem::current_path();
}

/// tests/data of the checkout: data made by other codes (GenGeo's cube1.geo ...), see its README.md.
inline std::filesystem::path reference_dir() {
  const char* s = std::getenv("BASALT_REFERENCE_DIR");
  return s && *s ? std::filesystem::path(s) : source_dir() / "tests" / "data";
}

/// A fresh scratch folder for one test, shared by all ranks (rank 0 creates it).
inline std::filesystem::path scratch_dir(const std::string& name) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / ("basalt-test-" + name + "-" + std::to_string(size()));
  if (rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  MPI_Barrier(world());
  return dir;
}

}  // namespace basalt::test
