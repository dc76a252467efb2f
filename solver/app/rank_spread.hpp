#pragma once
// basalt-run's end-of-run summary at more than one compute rank: how each phase's time per step spreads
// across the ranks (as LAMMPS's "MPI task timing breakdown" gives min, avg and max), so that a user sees a
// rank that computes more than the others, and the others waiting for it, without a profiler.
#include <array>
#include <string>
#include <vector>

namespace basalt::run {

/// The phases of solver::PhaseTimes, in the order of the "time per step" lines.
inline constexpr int kPhases = 5;
inline constexpr std::array<const char*, kPhases> kPhaseNames{"forces", "neighbour search", "communication",
                                                              "integration", "output"};

/// Two lines (each ending in '\n'): each phase's min / mean / max over the ranks in ms per step, and which
/// rank computed longest (forces, neighbour search and integration; its excess over the mean) and which
/// waited longest (communication). `times` holds kPhases seconds per rank, rank by rank (an all-gather of
/// each rank's PhaseTimes); `steps` > 0.
std::string rank_spread(const std::vector<double>& times, double steps);

}  // namespace basalt::run
