// libFuzzer target: the ESyS-Particle .geo reader (iolayer/src/geo_format.cpp) on arbitrary bytes. A
// file either reads (then it is valid: Geometry::validate passes, and it writes and reads back equal) or
// is refused with a FormatError naming the file and line; anything else is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "basalt/io/geometry.hpp"

namespace {

std::filesystem::path scratch(const char* name) {
  static const std::filesystem::path dir = [] {
    const char* t = std::getenv("TMPDIR");
    auto d = std::filesystem::path(t ? t : "/tmp") / ("basalt-fuzz-geo-" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir / name;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto in = scratch("in.geo");
  if (std::FILE* f = std::fopen(in.c_str(), "wb")) {
    if (size) std::fwrite(data, 1, size, f);
    std::fclose(f);
  } else {
    std::abort();
  }
  basalt::io::Geometry g;
  try {
    g = basalt::io::read_geo(in);
  } catch (const basalt::io::FormatError&) {
    return 0;
  }
  // Accepted: it must be valid, and survive a round trip unchanged.
  g.validate(in);
  const auto out = scratch("out.geo");
  basalt::io::write_geo(g, out);
  const auto back = basalt::io::read_geo(out);
  if (back.id != g.id || back.position != g.position || back.radius != g.radius || back.tag != g.tag ||
      back.bonds != g.bonds)
    std::abort();
  return 0;
}
