// Shared GoogleTest main for every Basalt test, serial or MPI.
//  - MPI is initialised once; tests use basalt::test::world() (never a bare MPI_COMM_WORLD in solver code).
//  - Only rank 0 prints GoogleTest's usual report; other ranks print their failed assertions,
//    prefixed with the rank, so nothing is lost.
//  - After every test the ranks agree on the outcome: a failure on any rank fails it on all
//    (rank 0 reports which ranks failed), and the exit code is the same everywhere.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cstdio>
#include <string>

namespace {

int g_rank = 0;
int g_size = 1;
int g_failed_tests = 0;  // tests that failed on some rank, as agreed by all ranks

class RankFailurePrinter : public testing::EmptyTestEventListener {
  void OnTestPartResult(const testing::TestPartResult& r) override {
    if (!r.failed()) return;
    std::fprintf(stderr, "[rank %d] %s:%d: Failure\n%s\n", g_rank, r.file_name() ? r.file_name() : "?",
                 r.line_number(), r.summary());
    std::fflush(stderr);
  }
};

class CrossRankVerdict : public testing::EmptyTestEventListener {
  void OnTestEnd(const testing::TestInfo& info) override {
    int mine = info.result()->Failed() ? 1 : 0;
    int any = 0;
    MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (!any) return;
    ++g_failed_tests;
    // Tell rank 0 which ranks failed so the report names them.
    std::string who;
    for (int r = 0; r < g_size; ++r) {
      int f = mine;
      MPI_Bcast(&f, 1, MPI_INT, r, MPI_COMM_WORLD);
      if (f) {
        if (!who.empty()) who.push_back(',');
        who.append(std::to_string(r));
      }
    }
    if (g_rank == 0 && g_size > 1)
      std::fprintf(stderr, "[  FAILED  ] %s.%s failed on rank(s) %s\n", info.test_suite_name(), info.name(),
                   who.c_str());
  }
};

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  testing::InitGoogleTest(&argc, argv);

  auto& listeners = testing::UnitTest::GetInstance()->listeners();
  if (g_rank != 0) {
    delete listeners.Release(listeners.default_result_printer());
    listeners.Append(new RankFailurePrinter);
  }
  listeners.Append(new CrossRankVerdict);

  int local = RUN_ALL_TESTS();
  int global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (g_failed_tests > 0) global = 1;
  MPI_Finalize();
  return global;
}
