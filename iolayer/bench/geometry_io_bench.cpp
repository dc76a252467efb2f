// Benchmark: how long reading and writing a large geometry takes in each format.
//   basalt-io-bench [particles=10000000] [bonds_per_particle=3] [repeats=3] [folder=/tmp]
// Prints the median of `repeats` runs for: .h5 write, .h5 read, .geo write, .geo read, and as a
// baseline the time to read the .h5 file's bytes into memory (page cache, same run), so the
// HDF5 read can be quoted as a ratio of plain I/O. Results go to docs/formats.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double median_seconds(int repeats, const std::function<void()>& f) {
  std::vector<double> t;
  for (int r = 0; r < repeats; ++r) {
    const auto start = Clock::now();
    f();
    t.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

basalt::io::Geometry make_geometry(std::size_t n, std::size_t bonds_per_particle) {
  basalt::io::Geometry g;
  const auto side = static_cast<std::size_t>(std::cbrt(double(n))) + 1;
  std::uint64_t state = 12345;
  auto next = [&] {  // splitmix64: reproducible everywhere
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const double x = double(i % side), y = double((i / side) % side), z = double(i / (side * side));
    g.add_particle(static_cast<std::int64_t>(i), {x + 0.01 * next(), y + 0.01 * next(), z},
                   0.2 + 0.3 * next(), static_cast<std::int32_t>(i % 4));
  }
  for (std::size_t i = 0; i + 1 < n; ++i)
    for (std::size_t k = 1; k <= bonds_per_particle && i + k < n; ++k)
      g.add_bond(static_cast<std::int64_t>(i), static_cast<std::int64_t>(i + k));
  g.box_max = {double(side), double(side), double(side)};
  return g;
}

}  // namespace

int main(int argc, char** argv) {
  const std::size_t n = argc > 1 ? std::stoull(argv[1]) : 10'000'000;
  const std::size_t bpp = argc > 2 ? std::stoull(argv[2]) : 3;
  const int repeats = argc > 3 ? std::stoi(argv[3]) : 3;
  const std::filesystem::path dir = argc > 4 ? argv[4] : std::filesystem::temp_directory_path();
  const auto h5 = dir / "basalt-io-bench.h5";
  const auto geo = dir / "basalt-io-bench.geo";

  const auto g = make_geometry(n, bpp);
  std::printf("particles %zu, bonds %zu, repeats %d (median)\n", g.size(), g.bonds.size(), repeats);
  try {
    const double h5_write = median_seconds(repeats, [&] { basalt::io::write_h5(g, h5); });
    std::size_t check = 0;
    const double h5_read = median_seconds(repeats, [&] { check += basalt::io::read_h5(h5).size(); });
    const double raw_read = median_seconds(repeats, [&] {
      std::ifstream in(h5, std::ios::binary);
      std::vector<char> bytes(std::filesystem::file_size(h5));
      in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      check += bytes.size() > 0;
    });
    const double geo_write = median_seconds(repeats, [&] { basalt::io::write_geo(g, geo); });
    const double geo_read = median_seconds(repeats, [&] { check += basalt::io::read_geo(geo).size(); });
    std::printf("h5  file %8.1f MB  write %7.3f s  read %7.3f s\n", std::filesystem::file_size(h5) / 1e6,
                h5_write, h5_read);
    std::printf("geo file %8.1f MB  write %7.3f s  read %7.3f s\n", std::filesystem::file_size(geo) / 1e6,
                geo_write, geo_read);
    std::printf("baseline: reading the .h5 bytes into memory %7.3f s\n", raw_read);
    std::printf("ratios: h5 read / raw read %.2f, geo read / h5 read %.1f (check %zu)\n", h5_read / raw_read,
                geo_read / h5_read, check);
  } catch (const basalt::io::FormatError& e) {
    std::fprintf(stderr, "basalt-io-bench: %s\n", e.what());
    return 1;
  }
  std::filesystem::remove(h5);
  std::filesystem::remove(geo);
  return 0;
}
