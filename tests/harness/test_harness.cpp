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

TEST(Harness, ReferenceDataIsBesideTheClone) {
  EXPECT_TRUE(std::filesystem::exists(basalt::test::reference_dir() / "cube1.geo"))
      << "expected ../shared/reference/cube1.geo next to the source tree, looked in "
      << basalt::test::reference_dir();
}
