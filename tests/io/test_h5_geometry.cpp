// Geometry in HDF5 (schema "basalt-geometry" v1): round trip, byte-for-byte determinism,
// atomic replacement, external readers (h5dump, h5py), and read_geometry's dispatch.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include "basalt/io/geometry.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace basalt::io;
using basalt::io::test::expect_format_error;
using basalt::io::test::read_bytes;
using basalt::io::test::sample_geometry;

namespace {

std::string run_and_capture(const std::string& command, const fs::path& out) {
  const int rc = std::system((command + " > " + out.string() + " 2>&1").c_str());
  EXPECT_EQ(rc, 0) << command << "\n" << read_bytes(out);
  return read_bytes(out);
}

}  // namespace

TEST(H5Geometry, RoundTripKeepsEverythingAndSortsById) {
  const auto dir = basalt::test::scratch_dir("h5-roundtrip");
  const Geometry g = sample_geometry();
  write_h5(g, dir / "g.h5");
  const Geometry back = read_h5(dir / "g.h5");

  Geometry expected = g;
  expected.sort_by_id();
  basalt::io::test::expect_same_particles_and_bonds(back, expected);
  EXPECT_EQ(back.id, (std::vector<std::int64_t>{3, 5, 8, 17, 40, 99}));
  EXPECT_EQ(back.bonds[1], (Bond{17, 40, 2}));  // written smaller id first
  EXPECT_EQ(back.box_min, g.box_min);
  EXPECT_EQ(back.box_max, g.box_max);
  EXPECT_EQ(back.periodic, g.periodic);
  EXPECT_EQ(back.units, g.units);
  EXPECT_EQ(back.attributes, g.attributes);
  EXPECT_EQ(back.statistics, g.statistics);
  EXPECT_FALSE(fs::exists(dir / "g.h5.tmp"));
}

TEST(H5Geometry, WithoutMassOrBondsOrParticles) {
  const auto dir = basalt::test::scratch_dir("h5-minimal");
  Geometry g;
  write_h5(g, dir / "empty.h5");
  const Geometry e = read_h5(dir / "empty.h5");
  EXPECT_EQ(e.size(), 0u);
  EXPECT_TRUE(e.bonds.empty());
  EXPECT_EQ(e.units, Units{});

  g.add_particle(1, {0, 0, 0}, 1.0);
  g.add_particle(2, {2, 0, 0}, 1.0);
  write_h5(g, dir / "nomass.h5");
  const Geometry n = read_h5(dir / "nomass.h5");
  EXPECT_FALSE(n.has_mass());
  EXPECT_EQ(n.size(), 2u);
  EXPECT_TRUE(n.bonds.empty());
}

TEST(H5Geometry, IdenticalInputGivesIdenticalBytes) {
  const auto dir = basalt::test::scratch_dir("h5-deterministic");
  const Geometry g = sample_geometry();
  write_h5(g, dir / "a.h5");
  // Object timestamps have one-second resolution: make sure a clock tick separates the writes.
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  write_h5(g, dir / "b.h5");
  const auto a = read_bytes(dir / "a.h5");
  EXPECT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == read_bytes(dir / "b.h5")) << "two writes of the same geometry differ";

  Geometry changed = g;
  changed.position[0][0] = std::nextafter(changed.position[0][0], 10.0);
  write_h5(changed, dir / "c.h5");
  EXPECT_FALSE(a == read_bytes(dir / "c.h5")) << "a one-ulp change must change the file";
}

TEST(H5Geometry, FailedWriteKeepsThePreviousFile) {
  const auto dir = basalt::test::scratch_dir("h5-keep");
  const auto file = dir / "g.h5";
  write_h5(sample_geometry(), file);
  const auto before = read_bytes(file);

  Geometry bad = sample_geometry();
  bad.radius[2] = -1;
  expect_format_error([&] { write_h5(bad, file); }, {file.string(), "radius"});

  // Fails half-way: the temporary file exists already when the reserved name is found.
  Geometry clash = sample_geometry();
  clash.attributes["schema"] = "mine";
  expect_format_error([&] { write_h5(clash, file); }, {file.string(), "attribute 'schema' of /", "reserves"});

  Geometry slash = sample_geometry();
  slash.statistics["a/b"] = {1.0};
  expect_format_error([&] { write_h5(slash, file); }, {file.string(), "/statistics/a/b", "not usable"});

  EXPECT_TRUE(read_bytes(file) == before);
  EXPECT_FALSE(fs::exists(dir / "g.h5.tmp"));
}

TEST(H5Geometry, UnwritableDestinationNamesThePath) {
  const auto dir = basalt::test::scratch_dir("h5-unwritable");
  basalt::io::test::write_bytes(dir / "plain-file", "x");
  const auto target = dir / "plain-file" / "g.h5";  // parent is a regular file: even root cannot write
  expect_format_error([&] { write_h5(sample_geometry(), target); }, {target.string(), "cannot create"});
  expect_format_error(
      [&] { write_geometry(sample_geometry(), dir / "missing-folder" / "g.geo"); },
      {(dir / "missing-folder" / "g.geo").string(), "cannot create: folder", "does not exist"});
  expect_format_error([&] { write_geometry(sample_geometry(), dir / "plain-file" / "g.geo"); },
                      {(dir / "plain-file" / "g.geo").string(), "is not a folder"});
}

TEST(H5Geometry, ReadableWithH5dumpAndH5py) {
  const auto dir = basalt::test::scratch_dir("h5-external");
  const auto file = dir / "g.h5";
  write_h5(sample_geometry(), file);

  const auto dump = run_and_capture("h5dump -A " + file.string(), dir / "dump.txt");
  EXPECT_NE(dump.find("\"basalt-geometry\""), std::string::npos) << dump;
  EXPECT_NE(dump.find("DATASET \"position\""), std::string::npos) << dump;
  EXPECT_NE(dump.find("DATASPACE  SIMPLE { ( 6, 3 ) / ( 6, 3 ) }"), std::string::npos) << dump;

  const auto script = dir / "check.py";
  std::ofstream(script)
      << "import h5py, sys\n"
         "f = h5py.File(sys.argv[1], 'r')\n"
         "print(f.attrs['schema'], int(f.attrs['schema_version']), f.attrs['length_unit'])\n"
         "print(list(f['particles/id'][:]), f['particles/position'].shape)\n"
         "print(f['particles/radius'][:].sum(), f['bonds/pairs'][1].tolist())\n";
  const auto out =
      run_and_capture("/usr/bin/python3 " + script.string() + " " + file.string(), dir / "py.txt");
  EXPECT_NE(out.find("basalt-geometry 1 m\n"), std::string::npos) << out;
  EXPECT_NE(out.find("[3, 5, 8, 17, 40, 99] (6, 3)\n"), std::string::npos) << out;
  EXPECT_NE(out.find("3.0 [17, 40]\n"), std::string::npos) << out;
}

TEST(ReadGeometry, DispatchesOnExtension) {
  const auto dir = basalt::test::scratch_dir("dispatch");
  const Geometry g = sample_geometry();
  write_geometry(g, dir / "g.H5");
  write_geometry(g, dir / "g.geo");
  EXPECT_EQ(read_geometry(dir / "g.H5").id, read_geometry(dir / "g.geo").id);
  EXPECT_EQ(read_bytes(dir / "g.H5").substr(1, 3), "HDF");
  EXPECT_EQ(read_bytes(dir / "g.geo").substr(0, 15), "LSMGeometry 1.2");
}

TEST(GeoFormat, WritesParticlesInIdOrderAndBondsSmallerIdFirst) {
  const auto dir = basalt::test::scratch_dir("geo-order");
  write_geo(sample_geometry(), dir / "g.geo");  // ids 40, 3, 17, 8, 99, 5 in memory
  const auto text = read_bytes(dir / "g.geo");
  EXPECT_NE(text.find("Simple\n6\n0.1 0.2 0.30000000000000004 0.25 3 2\n-1 1e-300 6.02214076e+23 0.3 5 -4\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("BeginConnect\n4\n3 8 1\n17 40 2\n5 99 0\n8 40 7\nEndConnect\n"), std::string::npos)
      << text;
}

TEST(ReadGeometry, UnknownExtensionIsNamed) {
  const auto dir = basalt::test::scratch_dir("unknown-ext");
  basalt::io::test::write_bytes(dir / "g.xyz", "1 2 3\n");
  expect_format_error([&] { read_geometry(dir / "g.xyz"); },
                      {"g.xyz", "unknown geometry format", ".h5", ".geo"});
  expect_format_error([&] { write_geometry(sample_geometry(), dir / "out.vtk"); },
                      {"out.vtk", "unknown geometry format"});
  EXPECT_FALSE(fs::exists(dir / "out.vtk"));
}

TEST(ReadGeometry, MissingFileIsNamed) {
  const auto dir = basalt::test::scratch_dir("missing-file");
  expect_format_error([&] { read_geometry(dir / "nope.h5"); }, {(dir / "nope.h5").string(), "no such file"});
  expect_format_error([&] { read_geometry(dir / "nope.geo"); },
                      {(dir / "nope.geo").string(), "no such file"});
  fs::create_directories(dir / "folder.h5");
  expect_format_error([&] { read_geometry(dir / "folder.h5"); }, {"folder.h5", "is a folder"});
}

TEST(H5Geometry, SparseAndNegativeIdsAreCheckedLikeDenseOnes) {
  const auto dir = basalt::test::scratch_dir("h5-sparse-ids");
  for (std::int64_t far : {std::int64_t{7}, std::int64_t{1} << 62}) {  // dense bitmap, then hash set
    Geometry g;
    g.add_particle(-3, {0, 0, 0}, 1);
    g.add_particle(far, {1, 0, 0}, 1);
    g.add_particle(0, {2, 0, 0}, 1);
    g.add_bond(far, -3);
    write_h5(g, dir / "g.h5");
    const auto back = read_h5(dir / "g.h5");
    EXPECT_EQ(back.id, (std::vector<std::int64_t>{-3, 0, far}));
    EXPECT_EQ(back.bonds[0], (Bond{-3, far, 0}));

    Geometry missing = g;
    missing.add_bond(0, far - 1);
    expect_format_error([&] { write_h5(missing, dir / "m.h5"); },
                        {"m.h5: bond 1", fmt::format("particle id {}, which does not exist", far - 1)});
    Geometry duplicate = g;
    duplicate.add_particle(far, {3, 0, 0}, 1);
    expect_format_error([&] { write_h5(duplicate, dir / "d.h5"); },
                        {"d.h5", fmt::format("duplicate id {}", far)});
  }
}

TEST(H5Geometry, FileWrittenWithH5pyFromTheDocsIsRead) {
  const auto dir = basalt::test::scratch_dir("h5-from-h5py");
  const auto file = dir / "made-by-h5py.h5";
  const auto script = dir / "make.py";
  // Written as a user following docs/formats.md would, with h5py's default types (int64 tags,
  // int64 periodic flags, no /statistics group).
  std::ofstream(script)
      << "import h5py, numpy as np, sys\n"
         "with h5py.File(sys.argv[1], 'w') as f:\n"
         "    f.attrs['schema'] = 'basalt-geometry'\n"
         "    f.attrs['schema_version'] = 1\n"
         "    for k, v in [('length', 'mm'), ('time', 'ms'), ('force', 'N'), ('mass', '')]:\n"
         "        f.attrs[k + '_unit'] = v\n"
         "    f.attrs['box_min'] = [0.0, 0.0, 0.0]\n"
         "    f.attrs['box_max'] = [3.0, 1.0, 1.0]\n"
         "    f.attrs['periodic'] = [0, 0, 1]\n"
         "    f.attrs['creator'] = 'a python script'\n"
         "    f['particles/id'] = np.array([2, 5, 9])\n"
         "    f['particles/position'] = np.array([[0.5, 0.5, 0.5], [1.5, 0.5, 0.5], [2.5, 0.5, 0.5]])\n"
         "    f['particles/radius'] = np.full(3, 0.5)\n"
         "    f['particles/tag'] = np.array([1, 1, 2])\n"
         "    f['bonds/pairs'] = np.array([[2, 5], [5, 9]])\n"
         "    f['bonds/tag'] = np.zeros(2, dtype=np.int32)\n";
  run_and_capture("/usr/bin/python3 " + script.string() + " " + file.string(), dir / "py.txt");
  const Geometry g = read_geometry(file);
  EXPECT_EQ(g.id, (std::vector<std::int64_t>{2, 5, 9}));
  EXPECT_EQ(g.position[2], (Vec3{2.5, 0.5, 0.5}));
  EXPECT_EQ(g.tag, (std::vector<std::int32_t>{1, 1, 2}));
  EXPECT_EQ(g.bonds[1], (Bond{5, 9, 0}));
  EXPECT_EQ(g.periodic, (std::array<bool, 3>{false, false, true}));
  EXPECT_EQ(g.attributes.at("creator"), "a python script");
  EXPECT_TRUE(g.statistics.empty());
}
