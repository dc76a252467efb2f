// The test harness itself: ranks see each other and the data folders are where tests expect them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "test_support.hpp"

TEST(Harness, AllRanksTakePartInACollective) {
  int one = 1;
  int sum = 0;
  MPI_Allreduce(&one, &sum, 1, MPI_INT, MPI_SUM, basalt::test::world());
  EXPECT_EQ(sum, basalt::test::size());
}

TEST(Harness, ScratchDirIsSharedAndEmpty) {
  auto dir = basalt::test::scratch_dir("harness");
  EXPECT_TRUE(std::filesystem::is_directory(dir));
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  MPI_Barrier(basalt::test::world());
}

// The data the tests read lives in the checkout (tests/data), never beside it: a clone with nothing
// beside it must pass.
TEST(Harness, ReferenceDataIsInsideTheCheckout) {
  namespace fs = std::filesystem;
  const fs::path geo = basalt::test::reference_dir() / "cube1.geo";
  ASSERT_TRUE(fs::exists(geo)) << "expected tests/data/cube1.geo in the source tree, looked in "
                               << basalt::test::reference_dir();
  const fs::path src = fs::canonical(basalt::test::source_dir());
  const fs::path rel = fs::canonical(geo).lexically_relative(src);
  EXPECT_TRUE(!rel.empty() && *rel.begin() != "..")
      << fs::canonical(geo) << " lies outside the checkout " << src;
}
