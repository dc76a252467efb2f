#pragma once
// Restart without any rank holding the whole checkpoint (issue 14), as GeometryLoader starts a run from a
// geometry file. Each compute rank reads one equal slice of the checkpoint's particle rows, bond rows,
// /bonds/break_position rows (those of the broken bonds among its bond rows) and contact rows (HDF5
// hyperslabs through io::CheckpointFile), then the ranks route what they read:
//  1. particles, with every per-particle dataset, to the rank owning their position at the last rebuild
//     (their position for a checkpoint without it) under the restored decomposition;
//  2. bonds, with their state, break position and the current distance of their ends, to the owners of
//     both ends (the slice holding an id - ids are sorted, so slices are ranges of ids - tells each reader
//     the owners and positions of the ends it needs);
//  3. contact histories to the owners of both particles of the pair.
// What arrives is kept in file order, so each rank holds exactly the rows the whole-file restart kept of
// the checkpoint: the run is bit for bit the same (tests/solver/sliced_restart.sh).
#include <array>
#include <cstdint>
#include <vector>

#include "basalt/io/checkpoint.hpp"
#include "basalt/io/checkpoint_rows.hpp"
#include "basalt/solver/parallel/communicator.hpp"
#include "basalt/solver/parallel/decomposition.hpp"
#include "basalt/solver/parallel/id_slices.hpp"

namespace basalt::solver {

/// This rank's part of a checkpoint.
struct CheckpointPart {
  /// The particles it owns (ascending id) with their rows; the bonds with an owned end (file order) with
  /// their state and, for broken ones, break positions; the contacts with an owned end (file order); the
  /// header's walls, clock and attributes.
  io::Checkpoint c;
  /// Per bond of c: the distance of its ends at the checkpoint (set for broken bonds, 0 for others).
  std::vector<double> bond_length;
};

class CheckpointLoader {
 public:
  /// Collective: reads this rank's slices of the particle, bond, break-position and contact rows; checks
  /// ids ascending across slices and one break position per broken bond. A bad file is an InputError
  /// ("--restart: " and read_checkpoint's message) on every rank alike.
  CheckpointLoader(const io::CheckpointFile& file, const Comm& comm);
  /// The slices read (particles, bonds with their state, contacts): for checks of the whole file.
  const io::Checkpoint& slice() const { return slice_; }
  std::size_t first_bond() const { return bond_begin_; }
  std::size_t first_contact() const { return contact_begin_; }
  std::int64_t first_id() const { return first_; }
  std::int64_t last_id() const { return last_; }
  /// Collective: this rank's part under `dec` (see CheckpointPart). Checks what slices cannot alone: bond
  /// and contact ends exist, no pair bonded twice. Releases the slices.
  /// `origin`: the run's frame (run.precision = "mixed"; zero otherwise): positions are routed by where the
  /// frame puts them (CheckpointFrame), as the whole-checkpoint restart assigns them.
  CheckpointPart local_part(const Decomposition& dec, const std::array<double, 3>& origin);

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& what) const;

  const io::CheckpointFile& file_;
  const Comm& comm_;
  io::Checkpoint slice_;
  std::size_t bond_begin_ = 0, contact_begin_ = 0;
  std::int64_t first_ = 0, last_ = 0;
  IdSlices slices_;  ///< which rank's slice holds an id
};

/// Collective: the positions, from the ranks whose `held` (ids ascending, positions) has them, of the
/// `wanted` ids (each held by exactly one rank); in the order of `wanted`. Throws InputError naming an id
/// no rank holds.
std::vector<io::Vec3> positions_of(const Comm& comm, const std::vector<std::int64_t>& wanted,
                                   const std::vector<std::int64_t>& held_ids,
                                   const std::vector<io::Vec3>& held_positions);

}  // namespace basalt::solver
