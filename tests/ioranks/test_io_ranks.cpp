// The I/O-rank service end to end, with a stand-in for the solver: compute ranks hand over
// field partial sums and frame pieces; I/O ranks (or, at np 1, the compute rank itself) write
// fields.csv and checkpoints. Checked: the series sums every rank's partials in step order,
// checkpoints hold every particle sorted by id, an unwritable output folder reaches every
// compute rank as an error naming the path, and nothing hangs.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <sstream>

#include "basalt/io/io_ranks.hpp"
#include "test_support.hpp"

using namespace basalt::io;
namespace fs = std::filesystem;

namespace {

int io_ranks_for(int world_size) { return world_size >= 4 ? 2 : (world_size >= 2 ? 1 : 0); }

constexpr int kPerRank = 5;  // particles per compute rank unless a test asks for more

FramePiece piece_for(int c, int n_compute, std::int64_t step, std::uint32_t kinds, int per_rank) {
  FramePiece p;
  p.kinds = kinds;
  p.step = step;
  p.time = step * 0.5;
  p.source_rank = c;
  for (int k = 0; k < per_rank; ++k) {
    const std::int64_t id = c + std::int64_t(k) * n_compute;
    p.id.push_back(id);
    p.position.push_back({double(id), double(step), 1.0});
    p.velocity.push_back({0, 0, double(step) * id});
    p.radius.push_back(0.5);
    p.mass.push_back(1.0);
    p.tag.push_back(0);
  }
  // One bond per rank, between its first two particles.
  p.bonds.push_back({p.id[0], p.id[1], 0});
  p.bond_rest_length.push_back(double(n_compute));
  p.bond_broken.push_back(0);
  if (c == 0) p.walls.push_back({"base", {0, 0, double(step)}, {0, 0, 1}, {0, 0, 0}, {0, 0, 0}, {}});
  return p;
}

struct RunResult {
  OutputReport report;
  std::optional<std::string> client_error;
  RankLayout layout;
};

RunResult run_fake_solver(const OutputConfig& cfg, int steps, int per_rank = kPerRank) {
  RunResult res;
  res.layout = split_ranks(basalt::test::world(), io_ranks_for(basalt::test::size()));
  RunInfo info;
  info.box_max = {10, 10, 10};
  info.scene_text = "# test scene";
  info.dt = 0.5;  // sent once, stored in every checkpoint
  if (res.layout.is_io) {
    res.report = IoServer(res.layout, cfg).run();
    return res;
  }
  OutputClient client(res.layout, cfg, info);
  int c = 0;
  MPI_Comm_rank(res.layout.compute, &c);
  for (std::int64_t step = 0; step <= steps; ++step) {
    if (client.wants_fields(step)) {
      const double partials[2] = {double(c + 1), double(step)};
      client.submit_fields(step, step * 0.5, partials);
    }
    if (auto kinds = client.frame_kinds(step))
      client.submit_frame(piece_for(c, res.layout.n_compute, step, kinds, per_rank));
    client.poll();
  }
  res.report = client.finish();
  res.client_error = client.error();
  return res;
}

}  // namespace

TEST(IoRanks, FieldSeriesAndCheckpointsFromEveryRank) {
  const auto dir = basalt::test::scratch_dir("ioranks-ok");
  OutputConfig cfg;
  cfg.dir = dir;
  cfg.fields_every = 1;
  cfg.checkpoint_every = 10;
  cfg.field_names = {"rank_sum", "step_sum"};
  cfg.field_batch_rows = 7;  // not a divisor of the step count: the last batch is partial
  auto res = run_fake_solver(cfg, 30);
  const int P = res.layout.n_compute;
  EXPECT_FALSE(res.report.error.has_value()) << *res.report.error;
  EXPECT_EQ(res.report.checkpoints.files, 4u);
  EXPECT_EQ(res.report.fields.files, 1u);
  EXPECT_GT(res.report.checkpoints.bytes, 0u);
  MPI_Barrier(basalt::test::world());

  // fields.csv: header, then one row per step with the sums over all compute ranks.
  std::ifstream in(dir / "fields.csv");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "step,time,rank_sum,step_sum");
  int rows = 0;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string cell;
    std::vector<double> v;
    while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
    ASSERT_EQ(v.size(), 4u) << line;
    EXPECT_EQ(v[0], rows);
    EXPECT_EQ(v[1], rows * 0.5);
    EXPECT_EQ(v[2], P * (P + 1) / 2.0);
    EXPECT_EQ(v[3], double(rows) * P);
    ++rows;
  }
  EXPECT_EQ(rows, 31);

  for (int step : {0, 10, 20, 30}) {
    const auto path = dir / fmt::format("ckpt_{:06d}.h5", step);
    ASSERT_TRUE(is_complete_checkpoint(path)) << path;
    const auto c = read_checkpoint(path);
    EXPECT_EQ(c.step, step);
    EXPECT_EQ(c.dt, 0.5);
    ASSERT_EQ(c.size(), std::size_t(kPerRank * P));
    for (std::size_t i = 0; i < c.size(); ++i) {
      EXPECT_EQ(c.geometry.id[i], std::int64_t(i));
      EXPECT_EQ(c.geometry.position[i][1], double(step));
      EXPECT_EQ(c.velocity[i][2], double(step) * double(i));
    }
    EXPECT_EQ(c.geometry.bonds.size(), std::size_t(P));
    ASSERT_EQ(c.walls.size(), 1u);
    EXPECT_EQ(c.walls[0].position[2], double(step));
    EXPECT_EQ(c.scene_text, "# test scene");
  }
  EXPECT_EQ(latest_complete_checkpoint(dir), dir / "ckpt_000030.h5");
  free_layout(res.layout);
}

// Issue 16: a non-finite sum is written as nan or inf, never as an empty cell (which means "saver not
// due"): the due mask travels beside the values, also to the I/O ranks (Q >= 1), where a NaN used to
// stand for "not due".
TEST(IoRanks, NonFiniteSumsAreWrittenAndNotDueCellsStayEmpty) {
  const auto dir = basalt::test::scratch_dir("ioranks-nonfinite");
  OutputConfig cfg;
  cfg.dir = dir;
  cfg.fields_every = 1;
  cfg.field_names = {"nan_sum", "inf_sum", "every_other"};
  cfg.field_batch_rows = 3;
  RankLayout layout = split_ranks(basalt::test::world(), io_ranks_for(basalt::test::size()));
  const int P = layout.n_compute;
  if (layout.is_io) {
    (void)IoServer(layout, cfg).run();
  } else {
    OutputClient client(layout, cfg, RunInfo{});
    int c = 0;
    MPI_Comm_rank(layout.compute, &c);
    const double nan = std::numeric_limits<double>::quiet_NaN(),
                 inf = std::numeric_limits<double>::infinity();
    for (std::int64_t step = 0; step < 10; ++step) {
      const bool due_now = step % 2 == 0;
      // Rank 0's NaN makes the sum NaN, its inf the sum inf; the third column is not due at odd steps
      // (its value then is whatever the solver left there: here a NaN, or -0.0 on other ranks).
      const double partials[3] = {c == 0 ? -nan : 1.0, c == 0 ? inf : 1.0,
                                  due_now ? 2.0 : (c == 0 ? nan : -0.0)};
      const char due[3] = {1, 1, static_cast<char>(due_now)};
      client.submit_fields(step, step * 0.5, partials, due);
      client.poll();
    }
    const auto report = client.finish();
    EXPECT_FALSE(report.error.has_value());
  }
  MPI_Barrier(basalt::test::world());
  std::ifstream in(dir / "fields.csv");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "step,time,nan_sum,inf_sum,every_other");
  int rows = 0;
  while (std::getline(in, line)) {
    const std::string third = rows % 2 == 0 ? fmt::format("{}", 2.0 * P) : "";
    EXPECT_EQ(line, fmt::format("{},{},nan,inf,{}", rows, rows * 0.5, third));
    ++rows;
  }
  EXPECT_EQ(rows, 10);
  free_layout(layout);
}

TEST(IoRanks, UnwritableFolderReachesEveryComputeRank) {
  const auto dir = basalt::test::scratch_dir("ioranks-bad");
  const fs::path blocker = dir / "not-a-folder";
  if (basalt::test::rank() == 0) std::ofstream(blocker) << "x";
  MPI_Barrier(basalt::test::world());
  OutputConfig cfg;
  cfg.dir = blocker / "out";  // its parent is a regular file: nothing can be written there
  cfg.fields_every = 1;
  cfg.checkpoint_every = 5;
  cfg.field_names = {"a", "b"};
  auto res = run_fake_solver(cfg, 10);
  ASSERT_TRUE(res.report.error.has_value());
  EXPECT_NE(res.report.error->find("not-a-folder"), std::string::npos) << *res.report.error;
  if (!res.layout.is_io) {
    ASSERT_TRUE(res.client_error.has_value());
    EXPECT_NE(res.client_error->find("not-a-folder"), std::string::npos);
  }
  free_layout(res.layout);
}

TEST(IoRanks, SlowStorageIsBoundedAndMeasured) {
  // Storage throttled to 20 MB/s, frames of ~1 MB per rank (beyond MPI's eager limit, so a send
  // completes only once the I/O rank takes it) and one frame in flight: the compute ranks must
  // wait (and say so), yet every checkpoint arrives.
  const auto dir = basalt::test::scratch_dir("ioranks-slow");
  OutputConfig cfg;
  cfg.dir = dir;
  cfg.checkpoint_every = 1;
  cfg.max_frames_in_flight = 1;
  cfg.throttle_mb_per_s = 20;
  auto res = run_fake_solver(cfg, 5, 12000);
  EXPECT_FALSE(res.report.error.has_value());
  EXPECT_EQ(res.report.checkpoints.files, 6u);
  EXPECT_GT(res.report.checkpoints.write_seconds, 0.2);
  EXPECT_GT(res.report.compute_wait_seconds, 0.01);
  free_layout(res.layout);
}

TEST(IoRanks, RefusesMoreIoRanksThanComputeRanks) {
  const int n = basalt::test::size();
  EXPECT_THROW(split_ranks(basalt::test::world(), n), std::invalid_argument);
  EXPECT_THROW(split_ranks(basalt::test::world(), -1), std::invalid_argument);
}
