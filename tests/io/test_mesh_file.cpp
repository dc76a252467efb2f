// Triangle-mesh files (STL ASCII and binary, OBJ, OFF): one cube in every format gives the same welded
// mesh, and every kind of bad input is refused with the file and the line (or byte offset) named.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "basalt/io/mesh_file.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace basalt::io;
using basalt::io::test::expect_format_error;
using basalt::io::test::write_bytes;

namespace {

// The unit cube: vertex i at (i & 1, i >> 1 & 1, i >> 2 & 1); faces counter-clockwise seen from outside.
Vec3 cube_vertex(int i) { return {double(i & 1), double(i >> 1 & 1), double(i >> 2 & 1)}; }
const std::vector<std::array<int, 4>> kCubeQuads = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                                    {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
std::vector<std::array<int, 3>> cube_triangles() {
  std::vector<std::array<int, 3>> t;
  for (const auto& q : kCubeQuads) t.push_back({q[0], q[1], q[2]}), t.push_back({q[0], q[2], q[3]});
  return t;
}

std::string ascii_stl(const std::vector<std::array<Vec3, 3>>& tris) {
  std::ostringstream s;
  s.precision(17);
  s << "solid cube\n";
  for (const auto& t : tris) {
    s << "  facet normal 0 0 0\n    outer loop\n";
    for (const auto& v : t) s << "      vertex " << v[0] << " " << v[1] << " " << v[2] << "\n";
    s << "    endloop\n  endfacet\n";
  }
  s << "endsolid cube\n";
  return s.str();
}

std::vector<std::array<Vec3, 3>> cube_facets() {
  std::vector<std::array<Vec3, 3>> f;
  for (const auto& t : cube_triangles())
    f.push_back({cube_vertex(t[0]), cube_vertex(t[1]), cube_vertex(t[2])});
  return f;
}

std::string binary_stl(const std::vector<std::array<Vec3, 3>>& tris) {
  std::string s(80, ' ');
  s.replace(0, 5, "solid");  // binary files that start with "solid" exist: the size decides
  auto put32 = [&](std::uint32_t x) {
    for (int k = 0; k < 4; ++k) s.push_back(static_cast<char>(x >> (8 * k) & 0xff));
  };
  put32(static_cast<std::uint32_t>(tris.size()));
  for (const auto& t : tris) {
    for (int k = 0; k < 3; ++k) put32(0);
    for (const auto& v : t)
      for (double x : v) put32(std::bit_cast<std::uint32_t>(static_cast<float>(x)));
    s.push_back(0), s.push_back(0);
  }
  return s;
}

// OBJ: quads, negative indices, v/vt/vn forms, comments, groups, texture and normal lines.
const char* kCubeObj = R"(# a cube
mtllib cube.mtl
o cube
v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
v 0 0 1
v 1 0 1
v 0 1 1
v 1 1 1 1.0
vt 0 0
vn 0 0 1
g bottom
f 1 3 4 2
f 5/1 6/1 8/1 7/1
s off
f 1//1 2//1 6//1 5//1
f -6/1/1 -2/1/1 -1/1/1 -5/1/1
f 1 5 7 3
f 2 4 8 6
)";

const char* kCubeOff = R"(OFF
# vertices faces edges
8 6 12
0 0 0
1 0 0
0 1 0
1 1 0
0 0 1
1 0 1
0 1 1
1 1 1
4 0 2 3 1
4 4 5 7 6
4 0 1 5 4
4 2 6 7 3   255 0 0
4 0 4 6 2
4 1 3 7 5
)";

/// The mesh as a sorted list of triangles of coordinates, each rotated to start at its smallest vertex
/// (winding kept): equal for equal meshes whatever the vertex numbering.
std::vector<std::array<Vec3, 3>> canonical(const TriangleMesh& m) {
  std::vector<std::array<Vec3, 3>> out;
  for (const auto& t : m.triangles) {
    std::array<Vec3, 3> c{m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]};
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    out.push_back(c);
  }
  std::sort(out.begin(), out.end());
  return out;
}

class MeshFile : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = basalt::test::scratch_dir("mesh-file"); }
  fs::path write(const std::string& name, const std::string& bytes) {
    write_bytes(dir_ / name, bytes);
    return dir_ / name;
  }
  void expect_error(const fs::path& file, std::initializer_list<std::string> fragments,
                    const MeshReadOptions& opt = {}) {
    expect_format_error([&] { read_mesh(file, opt); }, fragments);
  }
  fs::path dir_;
};

}  // namespace

TEST_F(MeshFile, ACubeInEveryFormatIsTheSameWeldedMesh) {
  const auto stl = read_mesh(write("cube.stl", ascii_stl(cube_facets())));
  const auto bin = read_mesh(write("cube_bin.STL", binary_stl(cube_facets())));
  const auto obj = read_mesh(write("cube.obj", kCubeObj));
  const auto off = read_mesh(write("cube.off", kCubeOff));
  for (const auto* m : {&stl, &bin, &obj, &off}) {
    EXPECT_EQ(m->vertices.size(), 8u);
    EXPECT_EQ(m->triangles.size(), 12u);
    EXPECT_EQ(m->dropped_degenerate, 0u);
    // Winding kept: every normal points out of the cube.
    for (const auto& t : m->triangles) {
      const auto &a = m->vertices[t[0]], &b = m->vertices[t[1]], &c = m->vertices[t[2]];
      const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const Vec3 n{u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      double out = 0;
      for (int d = 0; d < 3; ++d) out += n[d] * ((a[d] + b[d] + c[d]) / 3 - 0.5);
      EXPECT_GT(out, 0);
    }
  }
  EXPECT_EQ(stl.vertices_read, 36u);
  EXPECT_EQ(canonical(stl), canonical(bin));
  EXPECT_EQ(canonical(stl), canonical(obj));
  EXPECT_EQ(canonical(stl), canonical(off));
}

TEST_F(MeshFile, WeldingMergesExactCopiesAndOptionallyNearOnes) {
  auto facets = cube_facets();
  facets[3][1][0] += 1e-9;  // one copy of a vertex slightly off
  const auto file = write("near.stl", ascii_stl(facets));
  EXPECT_EQ(read_mesh(file).vertices.size(), 9u);
  MeshReadOptions opt;
  opt.weld_tolerance = 1e-6;
  const auto m = read_mesh(file, opt);
  EXPECT_EQ(m.vertices.size(), 8u);
  EXPECT_EQ(m.triangles.size(), 12u);
  // -0 and +0 are the same coordinate.
  auto neg = cube_facets();
  for (auto& t : neg)
    for (auto& v : t)
      for (auto& x : v)
        if (x == 0) x = -0.0;
  neg[0][0][0] = 0.0;
  EXPECT_EQ(read_mesh(write("negzero.stl", ascii_stl(neg))).vertices.size(), 8u);
}

TEST_F(MeshFile, DegenerateTrianglesAreDroppedAndCountedOrRefused) {
  auto facets = cube_facets();
  facets.push_back({Vec3{0, 0, 0}, Vec3{0.5, 0.5, 0.5}, Vec3{1, 1, 1}});  // collinear: zero area
  facets.push_back({Vec3{0, 0, 0}, Vec3{0, 0, 0}, Vec3{1, 1, 1}});        // repeated vertex
  const auto file = write("degenerate.stl", ascii_stl(facets));
  const auto m = read_mesh(file);
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.vertices.size(), 8u);  // the collinear triangle's midpoint is not kept
  EXPECT_EQ(m.dropped_degenerate, 2u);
  EXPECT_EQ(m.first_degenerate_where, "line 86");  // facet 13 starts at line 2 + 7 * 12
  MeshReadOptions refuse;
  refuse.degenerate = MeshReadOptions::Degenerate::refuse;
  expect_error(file, {"degenerate.stl", "line 86", "degenerate (zero-area) triangle"}, refuse);
  // Only degenerate triangles: an empty mesh.
  expect_error(write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"),
               {"flat.obj", "no triangles", "all 1 are degenerate", "line 4"});
}

TEST_F(MeshFile, FileErrors) {
  expect_error(dir_ / "missing.stl", {"missing.stl", "no such file"});
  expect_error(write("cube.ply", "ply\n"), {"cube.ply", "unknown mesh format '.ply'"});
  expect_error(write("empty.obj", "# nothing\nv 0 0 0\n"), {"empty.obj", "no triangles"});
  expect_error(write("empty.stl", ""), {"empty.stl", "too short for a binary STL"});
  expect_error(write("none.stl", "solid x\nendsolid x\n"), {"none.stl", "no triangles"});
}

TEST_F(MeshFile, BinaryStlErrorsNameTheByteOffset) {
  const auto good = binary_stl(cube_facets());
  expect_error(
      write("trunc.stl", good.substr(0, good.size() - 30)),
      {"trunc.stl", "byte offset 634", "truncated binary STL", "12 triangles", "triangle 11 is incomplete"});
  expect_error(write("long.stl", good + "xyz"),
               {"long.stl", "byte offset 684", "3 bytes after the 12 triangles"});
  auto bad = good;
  const float inf = INFINITY;
  std::memcpy(&bad[84 + 50 * 2 + 12 + 4], &inf, 4);  // triangle 2, first vertex, y
  expect_error(write("inf.stl", bad), {"inf.stl", "byte offset 200", "triangle 2", "not finite"});
}

TEST_F(MeshFile, AsciiStlErrorsNameTheLine) {
  const auto good = ascii_stl(cube_facets());
  auto replace_line = [&](int line, const std::string& text) {
    std::istringstream in(good);
    std::string out, l;
    for (int n = 1; std::getline(in, l); ++n) out += (n == line ? text : l) + "\n";
    return out;
  };
  expect_error(write("num.stl", replace_line(4, "      vertex 0 0x1 0")),
               {"num.stl", "line 4", "coordinate '0x1' is not a valid number"});
  expect_error(write("nan.stl", replace_line(5, "      vertex 0 nan 0")),
               {"nan.stl", "line 5", "'nan' is not finite"});
  expect_error(write("kw.stl", replace_line(3, "    outer lop")),
               {"kw.stl", "line 3", "expected 'outer loop', found 'outer lop'"});
  expect_error(write("two.stl", replace_line(4, "      vertex 0 0")),
               {"two.stl", "line 4", "3 coordinates, found 2"});
  expect_error(write("four.stl", replace_line(7, "      vertex 1 1 1\n    endloop")),
               {"four.stl", "line 8", "facet at line 2 has 4 vertices"});
  expect_error(write("cut.stl", good.substr(0, good.find("endloop"))),
               {"cut.stl", "line 8", "unexpected end of file", "expected 'vertex' or 'endloop'"});
  expect_error(write("junk.stl", good + "junk\n"), {"junk.stl", "line 87", "expected 'solid' or the end"});
}

TEST_F(MeshFile, ObjErrorsNameTheLine) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  expect_error(write("range.obj", v + "f 1 2 4\n"),
               {"range.obj", "line 4", "vertex index 4 is out of range (3 vertices defined so far)"});
  expect_error(write("neg.obj", v + "f -1 -2 -4\n"),
               {"neg.obj", "line 4", "vertex index -4 is out of range"});
  expect_error(write("zero.obj", v + "f 0 1 2\n"), {"zero.obj", "line 4", "vertex index 0"});
  expect_error(write("two.obj", v + "f 1 2\n"), {"two.obj", "line 4", "at least 3 vertices, found 2"});
  expect_error(write("idx.obj", v + "f 1 2 x/1\n"),
               {"idx.obj", "line 4", "vertex index 'x' is not a valid integer"});
  expect_error(write("coord.obj", "v 0 0 0\nv 1 0 zz\n"),
               {"coord.obj", "line 2", "'zz' is not a valid number"});
  expect_error(write("inf.obj", "v 0 0 0\nv 1 0 inf\n"), {"inf.obj", "line 2", "not finite"});
  expect_error(write("big.obj", "v 0 0 0\nv 1 0 1e999\n"), {"big.obj", "line 2", "out of range"});
  // A pentagon is fan-triangulated into three triangles.
  const auto m = read_mesh(write("pent.obj", "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\nf 1 2 3 4 5\n"));
  EXPECT_EQ(m.triangles.size(), 3u);
  EXPECT_EQ(m.triangles[2], (std::array<std::int32_t, 3>{0, 3, 4}));
}

TEST_F(MeshFile, OffErrorsNameTheLine) {
  std::string good = kCubeOff;
  auto with = [&](const std::string& from, const std::string& to) {
    auto s = good;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  expect_error(write("head.off", with("OFF", "COFF")), {"head.off", "line 1", "expected 'OFF'"});
  expect_error(write("range.off", with("4 1 3 7 5", "4 1 3 7 8")),
               {"range.off", "line 17", "vertex index 8 is out of range (0 to 7)"});
  expect_error(write("short.off", with("4 1 3 7 5", "4 1 3 7")), {"short.off", "line 17", "lists 3 indices"});
  expect_error(write("cut.off", with("4 1 3 7 5\n", "")),
               {"cut.off", "line 17", "unexpected end of file", "face 6 of 6"});
  expect_error(write("num.off", with("1 1 0\n", "1 1 z\n")),
               {"num.off", "line 7", "'z' is not a valid number"});
  expect_error(write("count.off", with("8 6 12", "8 six 12")), {"count.off", "line 3", "face count 'six'"});
  // Counts on the keyword's line are accepted too.
  EXPECT_EQ(read_mesh(write("inline.off", with("OFF\n# vertices faces edges\n8 6 12", "OFF 8 6 12"))).size(),
            12u);
}

TEST_F(MeshFile, TheShippedSiloLoads) {
  const auto file = basalt::test::source_dir() / "scenes" / "meshes" / "silo.stl";
  const auto m = read_mesh(file);
  // 64 facets: rings at the orifice, the bottom's rim and the top; side and bottom 2 x 64 triangles each.
  EXPECT_EQ(m.vertices.size(), 3u * 64);
  EXPECT_EQ(m.triangles.size(), 4u * 64);
  EXPECT_EQ(m.dropped_degenerate, 0u);
  Vec3 lo{1e9, 1e9, 1e9}, hi{-1e9, -1e9, -1e9};
  std::size_t orifice = 0;
  for (const auto& v : m.vertices) {
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], v[d]), hi[d] = std::max(hi[d], v[d]);
    orifice += std::abs(std::hypot(v[0], v[1]) - 4) < 1e-12 && v[2] == 0;
  }
  EXPECT_EQ(orifice, 64u);
  EXPECT_NEAR(hi[0] - lo[0], 40, 1e-12);
  EXPECT_NEAR(hi[1] - lo[1], 40, 1e-2);  // 64-gon: the y extent is the diameter times cos(pi / 64)
  EXPECT_EQ(lo[2], 0);
  EXPECT_EQ(hi[2], 60);
}
