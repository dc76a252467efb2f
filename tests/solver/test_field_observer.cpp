// FieldObserver (output/field_observer.hpp) on its own: a row goes to the sink only at steps where a saver
// is due, with this rank's partials and the due mask; saved() gives a column's sum over the ranks at the step
// it was saved and nothing at other steps or for columns not due; the FieldRows adapter is one object kept
// across calls and retargeted. On 1 and 2 ranks (each rank adds its own partials).
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "basalt/solver/output/field_observer.hpp"
#include "basalt/solver/parallel/communicator.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;

namespace {

/// An OutputSink that keeps the field rows this rank hands over.
class RowsHanded final : public OutputSink {
 public:
  struct Row {
    std::int64_t step;
    double time;
    std::vector<double> partials;
    std::vector<char> due;
  };
  std::vector<Row> rows;
  void begin(const std::vector<std::string>&) override {}
  void fields(std::int64_t step, double time, std::span<const double> local,
              std::span<const char> due) override {
    rows.push_back({step, time, {local.begin(), local.end()}, {due.begin(), due.end()}});
  }
  std::uint32_t frame_kinds(std::int64_t) const override { return 0; }
  void frame(const basalt::io::FrameSource&) override {}
  std::optional<std::string> poll() override { return std::nullopt; }
  bool continue_on_error() const override { return false; }
  void flush() override {}
};

/// Savers of two columns: column 0 due every 2 steps, column 1 every 3; this rank's partials are
/// (rank + 1) * step and 10 (rank + 1). Returns whether any is due.
auto savers(int rank) {
  return [rank](std::int64_t step) {
    return [rank, step](std::vector<double>& local, std::vector<char>& due) {
      local = {double(rank + 1) * double(step), 10.0 * (rank + 1)};
      due = {char(step % 2 == 0), char(step % 3 == 0)};
      return due[0] || due[1];
    };
  };
}

}  // namespace

TEST(FieldObserver, HandsRowsOnlyAtDueSteps) {
  const Comm comm(basalt::test::world());
  FieldObserver obs;
  RowsHanded out;
  const auto at = savers(comm.rank());
  for (std::int64_t s = 1; s <= 6; ++s) obs.observe(s, 0.5 * double(s), out, at(s));
  ASSERT_EQ(out.rows.size(), 4u);  // steps 2, 3, 4, 6
  EXPECT_EQ(out.rows[0].step, 2);
  EXPECT_EQ(out.rows[0].time, 1.0);
  EXPECT_EQ(out.rows[1].step, 3);
  EXPECT_EQ(out.rows[2].step, 4);
  EXPECT_EQ(out.rows[3].step, 6);
  const double r1 = comm.rank() + 1;
  EXPECT_EQ(out.rows[1].partials, (std::vector<double>{3 * r1, 10 * r1}));
  EXPECT_EQ(out.rows[1].due, (std::vector<char>{0, 1}));
  EXPECT_EQ(out.rows[3].due, (std::vector<char>{1, 1}));
}

TEST(FieldObserver, SavedSumsTheRanksPartialsAtTheSavedStepOnly) {
  const Comm comm(basalt::test::world());
  const int n = comm.size();
  const double ranks = n * (n + 1) / 2.0;  // sum of rank + 1 over the ranks
  FieldObserver obs;
  RowsHanded out;
  const auto at = savers(comm.rank());
  EXPECT_FALSE(obs.saved(0, 0, comm));  // nothing saved yet
  obs.observe(4, 2.0, out, at(4));      // column 0 due, column 1 not
  EXPECT_EQ(obs.saved(0, 4, comm), 4 * ranks);
  EXPECT_FALSE(obs.saved(1, 4, comm));  // not due at 4
  EXPECT_FALSE(obs.saved(2, 4, comm));  // no such column
  EXPECT_FALSE(obs.saved(0, 5, comm));  // asked at another step
  obs.observe(5, 2.5, out, at(5));      // none due
  EXPECT_FALSE(obs.saved(0, 5, comm));
  EXPECT_FALSE(obs.saved(1, 5, comm));
  obs.observe(6, 3.0, out, at(6));
  EXPECT_EQ(obs.saved(0, 6, comm), 6 * ranks);
  EXPECT_EQ(obs.saved(1, 6, comm), 10 * ranks);
  EXPECT_FALSE(obs.saved(0, 4, comm));
}

TEST(FieldObserver, KeepsOneFieldRowsAdapterAndRetargetsIt) {
  const Comm comm(basalt::test::world());
  const int n = comm.size();
  FieldObserver obs;
  basalt::test::MemorySink a, b;
  FieldRows& first = obs.rows(comm, &a);
  FieldRows& again = obs.rows(comm, &b);
  EXPECT_EQ(&first, &again);
  const auto at = savers(comm.rank());
  obs.observe(6, 3.0, again, at(6));
  obs.rows(comm, &b).finish();  // (more than one rank: the row's sum is delivered one row late)
  if (comm.rank() == 0) {
    EXPECT_TRUE(a.rows.empty());
    ASSERT_EQ(b.rows.size(), 1u);
    EXPECT_EQ(b.steps[0], 6);
    EXPECT_EQ(b.rows[0][0], 6 * n * (n + 1) / 2.0);
    EXPECT_EQ(b.rows[0][1], 10 * n * (n + 1) / 2.0);
  }
}
