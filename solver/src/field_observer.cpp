#include "basalt/solver/output/field_observer.hpp"

namespace basalt::solver {

std::optional<double> FieldObserver::saved(std::size_t column, std::int64_t now, const Comm& comm) const {
  if (step_ != now || column >= due_.size() || !due_[column]) return std::nullopt;
  const double v = local_[column];
  return comm.size() > 1 ? comm.sum(v) : v;
}

FieldRows& FieldObserver::rows(const Comm& comm, FieldSink* sink) {
  if (!rows_)
    rows_ = std::make_unique<FieldRows>(comm, sink);
  else
    rows_->retarget(sink);
  return *rows_;
}

}  // namespace basalt::solver
