// The XDMF descriptions of checkpoints (basalt/io/xdmf.hpp) as ParaView's three readers need them
// (docs/reliability.md, "ParaView's three XDMF readers"): every grid's Polyvertex topology has an
// explicit connectivity (a HyperSlab of the shared vertex file, which holds 0..M-1 and grows only with
// the particle count), a lone checkpoint's grid is inside a temporal collection (so the Xdmf3 readers see
// its time), and the series upgrades grids written without connectivity. tests/paraview/xdmf_readers.py
// opens the same files in ParaView itself.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "basalt/io/xdmf.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace basalt::io;
using basalt::io::test::expect_format_error;
using basalt::io::test::read_bytes;
using basalt::io::test::write_bytes;

namespace {

Checkpoint particles(std::size_t n, std::int64_t step, double time) {
  Checkpoint c;
  for (std::size_t i = 0; i < n; ++i)
    c.geometry.add_particle(static_cast<std::int64_t>(10 + i), {double(i), 0, 0}, 0.5);
  c.step = step;
  c.time = time;
  return c;
}

/// The text with each line's indentation removed: the checks below are about elements, not layout.
std::string unindented(const std::string& text) {
  std::string out;
  bool line_start = true;
  for (char ch : text) {
    if (line_start && ch == ' ') continue;
    line_start = ch == '\n';
    out += ch;
  }
  return out;
}

std::string connectivity(std::size_t n, std::size_t capacity) {
  return "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" + std::to_string(n) +
         "\" NodesPerElement=\"1\">\n"
         "<DataItem ItemType=\"HyperSlab\" Dimensions=\"" +
         std::to_string(n) +
         "\" NumberType=\"Int\" Precision=\"8\">\n"
         "<DataItem Dimensions=\"3 1\" Format=\"XML\">0 1 " +
         std::to_string(n) +
         "</DataItem>\n"
         "<DataItem Dimensions=\"" +
         std::to_string(capacity) +
         "\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">xdmf_vertices.h5:/vertices</DataItem>\n"
         "</DataItem>\n"
         "</Topology>\n";
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t k = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++k;
  return k;
}

/// /vertices of the vertex file, read with HDF5 itself (as ParaView's readers do), and its schema.
std::vector<std::int64_t> vertices(const fs::path& dir, std::string* schema = nullptr) {
  const hid_t f = H5Fopen((dir / kXdmfVerticesFile).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(f, 0);
  const hid_t d = H5Dopen2(f, "/vertices", H5P_DEFAULT);
  const hid_t s = H5Dget_space(d);
  hsize_t n = 0;
  H5Sget_simple_extent_dims(s, &n, nullptr);
  std::vector<std::int64_t> v(n);
  if (n) H5Dread(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  if (schema) {
    const hid_t a = H5Aopen(f, "schema", H5P_DEFAULT);
    const hid_t t = H5Aget_type(a);
    char* text = nullptr;
    H5Aread(a, t, &text);
    *schema = text ? text : "";
    H5free_memory(text);
    H5Tclose(t);
    H5Aclose(a);
  }
  H5Sclose(s);
  H5Dclose(d);
  H5Fclose(f);
  return v;
}

std::vector<std::int64_t> iota(std::size_t n) {
  std::vector<std::int64_t> v(n);
  std::iota(v.begin(), v.end(), 0);
  return v;
}

}  // namespace

TEST(Xdmf, CheckpointIsATemporalCollectionOfOneGridWithConnectivity) {
  const auto dir = basalt::test::scratch_dir("xdmf-one");
  write_checkpoint_xdmf(particles(5, 40, 0.04), dir / "ckpt_000040.h5");
  const std::string xml = unindented(read_bytes(dir / "ckpt_000040.xmf"));
  // The Xdmf3 readers see time only in a temporal collection: the grid is inside one, its <Time> in it.
  const auto collection =
      xml.find("<Grid Name=\"checkpoint\" GridType=\"Collection\" CollectionType=\"Temporal\">\n");
  const auto grid =
      xml.find("<Grid Name=\"particles\" GridType=\"Uniform\">\n<Time Value=\"0.040000000000000001\"/>");
  ASSERT_NE(collection, std::string::npos) << xml;
  ASSERT_NE(grid, std::string::npos) << xml;
  EXPECT_LT(collection, grid);
  EXPECT_EQ(count(xml, "</Grid>"), 2u);
  // The Xdmf3 readers make no cells from a Polyvertex topology without connectivity.
  EXPECT_NE(xml.find(connectivity(5, 5)), std::string::npos) << xml;
  EXPECT_EQ(count(xml, "<Topology"), 1u);
  EXPECT_EQ(xml.find("NodesPerElement=\"1\"/>"), std::string::npos) << "a topology without connectivity";
  EXPECT_NE(xml.find(">ckpt_000040.h5:/particles/position</DataItem>"), std::string::npos);
  std::string schema;
  EXPECT_EQ(vertices(dir, &schema), iota(5));
  EXPECT_EQ(schema, "basalt-xdmf-vertices");
  EXPECT_FALSE(fs::exists(dir / "xdmf_vertices.h5.partial"));
}

TEST(Xdmf, VertexFileGrowsOnlyWithTheParticleCount) {
  const auto dir = basalt::test::scratch_dir("xdmf-vertices");
  EXPECT_EQ(ensure_xdmf_vertices(dir, 5), 5u);
  const std::string five = read_bytes(dir / kXdmfVerticesFile);
  // Fewer particles: the file is left as it is (the HyperSlab reads its first N).
  EXPECT_EQ(ensure_xdmf_vertices(dir, 3), 5u);
  EXPECT_EQ(ensure_xdmf_vertices(dir, 5), 5u);
  EXPECT_EQ(read_bytes(dir / kXdmfVerticesFile), five);
  // More: rewritten with exactly that many, across several 64 Ki-row slabs, compressed.
  const std::size_t big = 150'001;
  EXPECT_EQ(ensure_xdmf_vertices(dir, big), big);
  EXPECT_EQ(vertices(dir), iota(big));
  EXPECT_LT(fs::file_size(dir / kXdmfVerticesFile), big * 8 / 20) << "not compressed";
  // Not ours, or damaged: written anew.
  write_bytes(dir / kXdmfVerticesFile, "not an HDF5 file");
  EXPECT_EQ(ensure_xdmf_vertices(dir, 4), 4u);
  EXPECT_EQ(vertices(dir), iota(4));
  // A folder that cannot take it: an error naming the file.
  expect_format_error([&] { ensure_xdmf_vertices(dir / "missing", 4); },
                      {"xdmf_vertices.h5", "does not exist"});
}

TEST(Xdmf, SeriesListsTimeOrderedGridsReadingTheVertexFileAsItIs) {
  const auto dir = basalt::test::scratch_dir("xdmf-series");
  // Checkpoints whose .h5 exists (the series lists only those), written out of time order, the later one
  // larger.
  for (const char* h5 : {"ckpt_000010.h5", "ckpt_000020.h5", "ckpt_000030.h5"}) write_bytes(dir / h5, "");
  write_checkpoint_xdmf(particles(7, 20, 0.2), dir / "ckpt_000020.h5");
  write_checkpoint_xdmf(particles(5, 10, 0.1), dir / "ckpt_000010.h5");
  write_checkpoint_xdmf(particles(9, 30, 0.3), dir / "ckpt_000030.h5");
  write_checkpoint_xdmf(particles(9, 40, 0.4), dir / "ckpt_000040.h5");  // no .h5: left out
  write_checkpoint_series_xdmf(dir, 20);  // after a restart from step 20: step 30 is left out too
  const std::string series = unindented(read_bytes(dir / "ckpt_series.xmf"));
  EXPECT_EQ(
      count(series, "<Grid Name=\"checkpoints\" GridType=\"Collection\" CollectionType=\"Temporal\">\n"), 1u);
  EXPECT_EQ(count(series, "<Grid Name=\"particles\""), 2u) << series;
  const auto first = series.find("<Time Value=\"0.10000000000000001\"/>");
  const auto second = series.find("<Time Value=\"0.20000000000000001\"/>");
  ASSERT_NE(first, std::string::npos);
  ASSERT_NE(second, std::string::npos);
  EXPECT_LT(first, second);
  // The vertex file holds 9 (step 30's): every listed grid says so, each reading its own first N.
  EXPECT_EQ(vertices(dir), iota(9));
  EXPECT_NE(series.find(connectivity(5, 9)), std::string::npos) << series;
  EXPECT_NE(series.find(connectivity(7, 9)), std::string::npos) << series;
  // A checkpoint's own file that stated another length is rewritten as the series lists it.
  EXPECT_NE(unindented(read_bytes(dir / "ckpt_000010.xmf")).find(connectivity(5, 9)), std::string::npos);
  EXPECT_NE(unindented(read_bytes(dir / "ckpt_000020.xmf")).find(connectivity(7, 9)), std::string::npos);
}

TEST(Xdmf, SeriesUpgradesCheckpointsWrittenWithoutConnectivity) {
  const auto dir = basalt::test::scratch_dir("xdmf-upgrade");
  // ckpt_000050.xmf as Basalt wrote it before issue 48: a lone grid, a topology without connectivity.
  write_bytes(dir / "ckpt_000050.h5", "");
  write_bytes(
      dir / "ckpt_000050.xmf",
      "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"3.0\">\n  <Domain>\n"
      "    <Grid Name=\"particles\" GridType=\"Uniform\">\n"
      "      <Time Value=\"0.050000000000000003\"/>\n"
      "      <Information Name=\"step\" Value=\"50\"/>\n"
      "      <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"4\" NodesPerElement=\"1\"/>\n"
      "      <Geometry GeometryType=\"XYZ\">\n"
      "        <DataItem Dimensions=\"4 3\" NumberType=\"Float\" Precision=\"8\" "
      "Format=\"HDF\">ckpt_000050.h5:/particles/position</DataItem>\n"
      "      </Geometry>\n"
      "    </Grid>\n  </Domain>\n</Xdmf>\n");
  write_checkpoint_series_xdmf(dir, 50);
  const std::string own = unindented(read_bytes(dir / "ckpt_000050.xmf"));
  const std::string series = unindented(read_bytes(dir / "ckpt_series.xmf"));
  for (const auto* xml : {&own, &series}) {
    EXPECT_NE(xml->find(connectivity(4, 4)), std::string::npos) << *xml;
    EXPECT_NE(
        xml->find("<Time Value=\"0.050000000000000003\"/>\n<Information Name=\"step\" Value=\"50\"/>\n"),
        std::string::npos);
    EXPECT_NE(xml->find(">ckpt_000050.h5:/particles/position</DataItem>\n</Geometry>\n</Grid>\n</Grid>\n"),
              std::string::npos)
        << *xml;
  }
  EXPECT_NE(own.find("<Grid Name=\"checkpoint\" GridType=\"Collection\" CollectionType=\"Temporal\">"),
            std::string::npos);
  EXPECT_EQ(vertices(dir), iota(4));
  // Once upgraded, writing the series again changes nothing.
  const std::string before = read_bytes(dir / "ckpt_000050.xmf");
  write_checkpoint_series_xdmf(dir, 50);
  EXPECT_EQ(read_bytes(dir / "ckpt_000050.xmf"), before);
}
