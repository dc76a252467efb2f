#include "basalt/solver/parallel/id_slices.hpp"

#include <algorithm>
#include <limits>

namespace basalt::solver {

IdSlices::IdSlices(const Comm& comm, const std::vector<std::int64_t>& ids) {
  const bool empty = ids.empty();
  const auto first = comm.all_gather(empty ? std::numeric_limits<std::int64_t>::max() : ids.front());
  const auto last = comm.all_gather(empty ? std::numeric_limits<std::int64_t>::min() : ids.back());
  for (std::size_t q = 0; q < first.size(); ++q) {
    if (first[q] > last[q]) continue;  // an empty slice holds no id
    rank_.push_back(static_cast<int>(q));
    first_.push_back(first[q]);
    last_.push_back(last[q]);
  }
}

int IdSlices::slice_of(std::int64_t id) const {
  // The last non-empty slice whose first id is <= id (the firsts ascend once disorder() found nothing).
  const auto it = std::upper_bound(first_.begin(), first_.end(), id);
  if (it == first_.begin()) return -1;
  const auto k = static_cast<std::size_t>(it - first_.begin()) - 1;
  return id <= last_[k] ? rank_[k] : -1;
}

std::optional<IdSlices::Disorder> IdSlices::disorder() const {
  for (std::size_t k = 1; k < first_.size(); ++k)
    if (first_[k] <= last_[k - 1]) return Disorder{rank_[k], first_[k], rank_[k - 1], last_[k - 1]};
  return std::nullopt;
}

std::int64_t IdSlices::first() const { return first_.empty() ? 0 : first_.front(); }
std::int64_t IdSlices::last() const { return last_.empty() ? 0 : last_.back(); }

}  // namespace basalt::solver
