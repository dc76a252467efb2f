#pragma once
// The ranges of ids that the ranks' slices of an id-sorted file hold (the sliced start-up and restart,
// issue 14): each rank reads an equal run of rows; since the rows are sorted by id, each slice is a
// range of ids, and the gathered ranges tell every rank which slice holds an id, and whether the file's
// order holds across slices.
#include <cstdint>
#include <optional>
#include <vector>

#include "basalt/solver/parallel/communicator.hpp"

namespace basalt::solver {

class IdSlices {
 public:
  IdSlices() = default;
  /// Collective: gathers every rank's range of ids; `ids`: this rank's slice (ascending, may be empty).
  IdSlices(const Comm& comm, const std::vector<std::int64_t>& ids);

  /// The rank whose slice holds id (by the ranges), or -1 when no slice's range covers it. Meaningful once
  /// disorder() found nothing (the ranges ascend).
  int slice_of(std::int64_t id) const;

  /// Where the ids stop ascending across slices: a non-empty slice whose first id is not above the last
  /// id of the non-empty slice before it.
  struct Disorder {
    int rank;               ///< the slice whose first id comes too early
    std::int64_t id;        ///< that first id
    int previous_rank;      ///< the non-empty slice before it
    std::int64_t previous;  ///< its last id
  };
  /// The first such place, or none when the slices' ranges ascend.
  std::optional<Disorder> disorder() const;

  /// The first id of the first non-empty slice and the last of the last one (0 when all are empty).
  std::int64_t first() const;
  std::int64_t last() const;

 private:
  // The non-empty slices in rank order: their rank, first and last id.
  std::vector<int> rank_;
  std::vector<std::int64_t> first_, last_;
};

}  // namespace basalt::solver
