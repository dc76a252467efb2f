#pragma once
// Shared by the HDF5 fuzz targets: the input bytes as a file the readers can open. The readers take a
// path (h5::Reader calls H5Fis_hdf5 and H5Fopen on it, with HDF5's default driver), so the bytes go to a
// file in /dev/shm (memory, no disk traffic), or in $TMPDIR when /dev/shm is missing. HDF5's automatic
// error printing is switched off once: the readers silence it themselves while they run, and the
// targets' own calls must not flood the fuzzer's output either.
#include <hdf5.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace basalt::fuzz {

inline std::filesystem::path h5_scratch(const char* target, const char* name) {
  static const std::filesystem::path dir = [target] {
    std::error_code ec;
    const char* t = std::getenv("TMPDIR");
    const std::filesystem::path base =
        std::filesystem::is_directory("/dev/shm", ec) ? "/dev/shm" : (t ? t : "/tmp");
    auto d = base / (std::string("basalt-") + target + "-" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return d;
  }();
  return dir / name;
}

/// Writes the bytes to `file`; aborts when it cannot (that is the harness failing, not the reader).
inline void write_input(const std::filesystem::path& file, const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(file.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  if (std::fclose(f) != 0) std::abort();
}

}  // namespace basalt::fuzz
