#include "basalt/solver/output/field_rows.hpp"

#include <optional>

namespace basalt::solver {

void FieldRows::fields(std::int64_t step, double time, std::span<const double> local_partials,
                       std::span<const char> due) {
  if (comm_.size() == 1) {
    if (!sink_) return;
    std::vector<std::optional<double>> row(local_partials.size());
    for (std::size_t c = 0; c < local_partials.size(); ++c)
      if (due[c]) row[c] = local_partials[c];
    sink_->row(step, time, row);
    return;
  }
  finish();
  if (!sum_) sum_ = std::make_unique<AsyncSum>(comm_);
  sum_->start(std::vector<double>(local_partials.begin(), local_partials.end()));
  step_ = step;
  time_ = time;
  due_.assign(due.begin(), due.end());
}

void FieldRows::finish() {
  if (!sum_ || !sum_->active()) return;
  const auto& sums = sum_->finish();
  if (comm_.rank() != 0 || !sink_) return;
  std::vector<std::optional<double>> row(sums.size());
  for (std::size_t c = 0; c < sums.size(); ++c)
    if (due_[c]) row[c] = sums[c];
  sink_->row(step_, time_, row);
}

void FieldRows::flush() {
  finish();
  if (sink_ && comm_.rank() == 0) sink_->flush();
}

}  // namespace basalt::solver
