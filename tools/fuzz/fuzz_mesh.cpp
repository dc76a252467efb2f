// libFuzzer target: the mesh-wall reader (iolayer/src/mesh_file.cpp) on arbitrary bytes. The first byte
// picks the format (.stl, .obj, .off), the rest is the file. A file either reads (then every vertex is
// finite, every index in range, no triangle repeats a vertex, and at least one triangle is kept) or is
// refused with a FormatError; anything else (a crash, a sanitizer report, another exception) is a finding.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "basalt/io/mesh_file.hpp"

namespace {

std::filesystem::path scratch(const char* name) {
  static const std::filesystem::path dir = [] {
    const char* t = std::getenv("TMPDIR");
    auto d = std::filesystem::path(t ? t : "/tmp") / ("basalt-fuzz-mesh-" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir / name;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const kNames[] = {"in.stl", "in.obj", "in.off"};
  const auto in = scratch(kNames[data[0] % 3]);
  if (std::FILE* f = std::fopen(in.c_str(), "wb")) {
    if (size > 1) std::fwrite(data + 1, 1, size - 1, f);
    std::fclose(f);
  } else {
    std::abort();
  }
  basalt::io::TriangleMesh m;
  try {
    basalt::io::MeshReadOptions opt;
    opt.weld_tolerance = (data[0] / 3) % 2 ? 1e-6 : 0.0;  // both welding paths
    m = basalt::io::read_mesh(in, opt);
  } catch (const basalt::io::FormatError&) {
    return 0;
  }
  if (m.triangles.empty()) std::abort();
  for (const auto& v : m.vertices)
    for (double c : v)
      if (!std::isfinite(c)) std::abort();
  const auto n = static_cast<std::int32_t>(m.vertices.size());
  for (const auto& t : m.triangles) {
    for (auto k : t)
      if (k < 0 || k >= n) std::abort();
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) std::abort();
  }
  return 0;
}
