// The formats under MPI: every rank reads the reference packing and round-trips it through its
// own files; rank 0 writes a shared file all ranks read; files written by different processes
// from the same geometry are byte-identical; a damaged file fails the same way on every rank.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace basalt::io;
using basalt::test::rank;
using basalt::test::size;
using basalt::test::world;

namespace {

std::uint64_t fnv1a(const std::string& bytes) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : bytes) h = (h ^ c) * 1099511628211ull;
  return h;
}

/// True on every rank when every rank passed the same value.
bool all_ranks_agree(std::uint64_t value) {
  std::vector<std::uint64_t> all(static_cast<std::size_t>(size()));
  MPI_Allgather(&value, 1, MPI_UINT64_T, all.data(), 1, MPI_UINT64_T, world());
  for (auto v : all)
    if (v != all[0]) return false;
  return true;
}

std::uint64_t fingerprint(const Geometry& g) {
  std::string bytes;
  auto add = [&](const void* p, std::size_t n) { bytes.append(static_cast<const char*>(p), n); };
  add(g.id.data(), g.id.size() * sizeof(g.id[0]));
  add(g.position.data(), g.position.size() * sizeof(g.position[0]));
  add(g.radius.data(), g.radius.size() * sizeof(double));
  add(g.tag.data(), g.tag.size() * sizeof(g.tag[0]));
  for (const auto& b : g.bonds) bytes += fmt::format("{} {} {};", b.a, b.b, b.tag);
  return fnv1a(bytes);
}

}  // namespace

TEST(IoParallel, EveryRankRoundTripsTheReferencePackingAndAgrees) {
  const auto dir = basalt::test::scratch_dir("io-parallel");
  const Geometry g = read_geometry(basalt::test::reference_dir() / "cube1.geo");
  EXPECT_EQ(g.size(), 8948u);
  EXPECT_EQ(g.bonds.size(), 30090u);

  // Each rank writes its own files from the same geometry.
  const auto mine = dir / fmt::format("cube.rank{}.h5", rank());
  write_geometry(g, mine);
  const Geometry h = read_geometry(mine);
  write_geometry(h, dir / fmt::format("cube.rank{}.geo", rank()));
  const Geometry back = read_geometry(dir / fmt::format("cube.rank{}.geo", rank()));
  basalt::io::test::expect_same_particles_and_bonds(back, g);

  EXPECT_TRUE(all_ranks_agree(fingerprint(back))) << "ranks read different geometries";
  EXPECT_TRUE(all_ranks_agree(fnv1a(basalt::io::test::read_bytes(mine))))
      << "the same geometry written by different processes gave different bytes";

  // Rank 0 writes one shared file; every rank reads it and finds what it holds itself.
  if (rank() == 0) write_geometry(g, dir / "shared.h5");
  MPI_Barrier(world());
  EXPECT_EQ(fingerprint(read_geometry(dir / "shared.h5")), fingerprint(g));
}

TEST(IoParallel, DamagedFileFailsTheSameWayOnEveryRank) {
  const auto dir = basalt::test::scratch_dir("io-parallel-bad");
  const auto file = dir / "half.h5";
  if (rank() == 0) {
    write_geometry(read_geometry(basalt::test::reference_dir() / "cube1.geo"), dir / "whole.h5");
    const auto bytes = basalt::io::test::read_bytes(dir / "whole.h5");
    basalt::io::test::write_bytes(file, bytes.substr(0, bytes.size() / 2));
    basalt::io::test::write_bytes(dir / "bad.geo", "LSMGeometry 1.2\nBoundingBox 0 0 0 1 1 1\n");
  }
  MPI_Barrier(world());
  std::string message;
  try {
    read_geometry(file);
  } catch (const FormatError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find(file.string() + ": file is truncated"), std::string::npos) << message;
  EXPECT_TRUE(all_ranks_agree(fnv1a(message)));

  basalt::io::test::expect_format_error([&] { read_geometry(dir / "bad.geo"); },
                                        {"bad.geo", "line 3", "PeriodicBoundaries"});
}
