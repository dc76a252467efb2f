// Malformed ESyS-Particle .geo files: every error names the file, the line and what is wrong.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace basalt::io;
using basalt::io::test::expect_format_error;

namespace {

// A valid file; line numbers below refer to this text (line 1 = "LSMGeometry 1.2").
const std::vector<std::string> kGood = {
    "LSMGeometry 1.2",             // 1
    "BoundingBox 0 0 0 10 10 10",  // 2
    "PeriodicBoundaries 0 0 0",    // 3
    "Dimension 3D",                // 4
    "BeginParticles",              // 5
    "Simple",                      // 6
    "4",                           // 7
    "1.0 1.0 1.0 0.5 10 1",        // 8
    "2.0 1.0 1.0 0.5 11 1",        // 9
    "3.0 1.0 1.0 0.5 12 1",        // 10
    "4.0 1.0 1.0 0.5 13 2",        // 11
    "EndParticles",                // 12
    "BeginConnect",                // 13
    "3",                           // 14
    "10 11 0",                     // 15
    "11 12 0",                     // 16
    "12 13 1",                     // 17
    "EndConnect",                  // 18
};

class GeoBadInput : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = basalt::test::scratch_dir("geo-bad"); }

  /// Writes kGood with line `line` (1-based) replaced; an empty replacement removes the line.
  fs::path with_line(std::size_t line, const std::string& text, std::size_t keep_lines = 0) {
    std::ostringstream out;
    for (std::size_t i = 0; i < kGood.size(); ++i) {
      if (keep_lines && i >= keep_lines) break;
      if (i + 1 == line) {
        if (!text.empty()) out << text << "\n";
      } else {
        out << kGood[i] << "\n";
      }
    }
    const auto file = dir_ / "bad.geo";
    basalt::io::test::write_bytes(file, out.str());
    return file;
  }
  fs::path first_lines(std::size_t n) { return with_line(0, "", n); }

  void expect_error(const fs::path& file, std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(basalt::io::test::read_bytes(file));
    expect_format_error([&] { read_geo(file); }, fragments);
  }

  fs::path dir_;
};

}  // namespace

TEST_F(GeoBadInput, TheUnmodifiedFileIsValid) {
  const auto g = read_geo(with_line(0, ""));
  EXPECT_EQ(g.size(), 4u);
  EXPECT_EQ(g.bonds.size(), 3u);
  EXPECT_EQ(g.box_max, (Vec3{10, 10, 10}));
  EXPECT_EQ(g.tag.back(), 2);
  // The particle section alone (no connections) is a valid file too.
  EXPECT_EQ(read_geo(first_lines(12)).bonds.size(), 0u);
}

TEST_F(GeoBadInput, TruncatedFile) {
  expect_error(first_lines(9), {"bad.geo", "line 10", "unexpected end of file", "particle line"});
  expect_error(first_lines(4), {"bad.geo", "line 5", "unexpected end of file", "BeginParticles"});
  expect_error(first_lines(16), {"bad.geo", "line 17", "unexpected end of file", "bond line"});
  // Cut in the middle of a line.
  expect_error(with_line(10, "3.0 1.0", 10), {"bad.geo", "line 10", "needs 6 fields", "found 2"});
  basalt::io::test::write_bytes(dir_ / "bad.geo", "");
  expect_error(dir_ / "bad.geo", {"bad.geo", "line 1", "unexpected end of file"});
}

TEST_F(GeoBadInput, ParticleCountTooSmallOrTooLarge) {
  expect_error(with_line(7, "3"), {"bad.geo", "line 11", "expected 'EndParticles' after 3 particles"});
  expect_error(with_line(7, "5"),
               {"bad.geo", "line 12", "particle count says 5, but only 4 particles follow"});
  expect_error(with_line(7, "-2"), {"bad.geo", "line 7", "particle count is negative"});
  expect_error(with_line(14, "4"), {"bad.geo", "line 18", "bond count says 4, but only 3 bonds follow"});
  expect_error(with_line(14, "2"), {"bad.geo", "line 17", "expected 'EndConnect' after 2 bonds"});
}

TEST_F(GeoBadInput, NonNumericField) {
  expect_error(with_line(9, "2.0 abc 1.0 0.5 11 1"), {"bad.geo", "line 9", "y 'abc' is not a valid number"});
  expect_error(with_line(10, "3.0 1.0 1.0 0.5 12x 1"),
               {"bad.geo", "line 10", "id '12x' is not a valid number"});
  expect_error(with_line(7, "four"), {"bad.geo", "line 7", "particle count 'four' is not a valid number"});
  expect_error(with_line(16, "11 twelve 0"), {"bad.geo", "line 16", "bond id2 'twelve'"});
  expect_error(with_line(2, "BoundingBox 0 0 0 10 ten 10"), {"bad.geo", "line 2", "BoundingBox value 'ten'"});
  expect_error(with_line(8, "nan 1.0 1.0 0.5 10 1"), {"bad.geo", "line 8", "position must be finite"});
}

TEST_F(GeoBadInput, BondToMissingId) {
  expect_error(with_line(16, "11 99 0"), {"bad.geo", "line 16", "particle id 99, which does not exist"});
  expect_error(with_line(16, "11 11 0"), {"bad.geo", "line 16", "joins particle 11 to itself"});
}

// Issue 16: a pair bonded twice (either order) would act as two springs; refused naming both bonds.
TEST_F(GeoBadInput, DuplicateBondsAreRefused) {
  expect_error(with_line(17, "10 11 0"),
               {"bad.geo", "bonds 0 and 2", "both join particles 10 and 11", "two springs"});
  expect_error(with_line(17, "11 10 0"), {"bad.geo", "bonds 0 and 2", "both join particles 10 and 11"});
  expect_error(with_line(17, "12 11 3"), {"bad.geo", "bonds 1 and 2", "both join particles 11 and 12"});
}

// Issue 16: a tag beyond the int32 range is named as out of range (not "not a valid number").
TEST_F(GeoBadInput, TagsBeyondInt32AreOutOfRange) {
  expect_error(with_line(9, "2.0 1.0 1.0 0.5 11 2147483648"),
               {"bad.geo", "line 9", "tag '2147483648' is out of range", "-2147483648 to 2147483647"});
  expect_error(with_line(9, "2.0 1.0 1.0 0.5 11 -2147483649"),
               {"bad.geo", "line 9", "tag '-2147483649' is out of range"});
  expect_error(with_line(16, "11 12 99999999999"),
               {"bad.geo", "line 16", "bond tag '99999999999' is out of range"});
  expect_error(with_line(9, "2.0 1.0 1.0 0.5 99999999999999999999 1"),
               {"bad.geo", "line 9", "id '99999999999999999999' is out of range"});
  // The extremes themselves are fine.
  EXPECT_EQ(read_geo(with_line(9, "2.0 1.0 1.0 0.5 11 2147483647")).tag[1], 2147483647);
  EXPECT_EQ(read_geo(with_line(9, "2.0 1.0 1.0 0.5 11 -2147483648")).tag[1], -2147483648LL);
}

TEST_F(GeoBadInput, NegativeOrZeroRadius) {
  expect_error(with_line(10, "3.0 1.0 1.0 -0.5 12 1"), {"bad.geo", "line 10", "radius", "got -0.5"});
  expect_error(with_line(10, "3.0 1.0 1.0 0 12 1"), {"bad.geo", "line 10", "radius", "> 0, got 0"});
  expect_error(with_line(10, "3.0 1.0 1.0 inf 12 1"), {"bad.geo", "line 10", "radius must be finite"});
}

TEST_F(GeoBadInput, DuplicateIds) {
  expect_error(with_line(11, "4.0 1.0 1.0 0.5 10 2"),
               {"bad.geo", "line 11", "duplicate particle id 10", "first on line 8"});
}

TEST_F(GeoBadInput, WrongSchemaNameOrNewerVersion) {
  expect_error(with_line(1, "LSMGeometrie 1.2"),
               {"bad.geo", "line 1", "first line must be 'LSMGeometry 1.2'"});
  expect_error(with_line(1, "LSMGeometry 1.3"),
               {"bad.geo", "line 1", "unsupported LSMGeometry version '1.3'"});
  expect_error(with_line(1, "LSMGeometry"), {"bad.geo", "line 1", "unsupported LSMGeometry version"});
  expect_error(with_line(4, "Dimension 2D"), {"bad.geo", "line 4", "only 'Dimension 3D'"});
}

TEST_F(GeoBadInput, MissingSection) {
  expect_error(with_line(3, ""), {"bad.geo", "line 3", "expected 'PeriodicBoundaries'"});
  expect_error(with_line(6, ""), {"bad.geo", "line 6", "expected 'Simple'"});
  expect_error(with_line(13, ""), {"bad.geo", "line 13", "expected 'BeginConnect'"});
  expect_error(with_line(18, ""), {"bad.geo", "line 18", "unexpected end of file", "EndConnect"});
}

TEST_F(GeoBadInput, MismatchedFieldCounts) {
  expect_error(with_line(9, "2.0 1.0 1.0 0.5 11"), {"bad.geo", "line 9", "needs 6 fields", "found 5"});
  expect_error(with_line(9, "2.0 1.0 1.0 0.5 11 1 7"), {"bad.geo", "line 9", "needs 6 fields", "found 7"});
  expect_error(with_line(15, "10 11"), {"bad.geo", "line 15", "needs 3 fields", "found 2"});
  expect_error(with_line(2, "BoundingBox 0 0 0 10 10"), {"bad.geo", "line 2", "takes 6 values, found 5"});
}

TEST_F(GeoBadInput, TextAfterTheEnd) {
  expect_error(with_line(18, "EndConnect\n\n  \ntrailing words"),
               {"bad.geo", "line 21", "after 'EndConnect'"});
}
