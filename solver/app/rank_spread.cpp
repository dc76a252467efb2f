#include "rank_spread.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstddef>

namespace basalt::run {

std::string rank_spread(const std::vector<double>& times, double steps) {
  const std::size_t ranks = times.size() / kPhases;
  if (ranks == 0 || steps <= 0) return {};
  const auto at = [&](std::size_t r, int k) { return times[r * kPhases + static_cast<std::size_t>(k)]; };
  const double ms = 1e3 / steps;
  std::string line = "time per step by rank (min / mean / max):";
  for (int k = 0; k < kPhases; ++k) {
    double lo = at(0, k), hi = lo, sum = 0;
    for (std::size_t r = 0; r < ranks; ++r) {
      lo = std::min(lo, at(r, k));
      hi = std::max(hi, at(r, k));
      sum += at(r, k);
    }
    line += fmt::format(" {} {:.4f} / {:.4f} / {:.4f} ms{}", kPhaseNames[static_cast<std::size_t>(k)],
                        lo * ms, sum / double(ranks) * ms, hi * ms, k + 1 < kPhases ? "," : "\n");
  }
  // Compute: what a rank does on its own particles; waiting: what it spends in the exchanges, most of it
  // waiting for the slowest rank's compute.
  std::size_t slow = 0, waits = 0;
  double compute_sum = 0;
  const auto compute = [&](std::size_t r) { return at(r, 0) + at(r, 1) + at(r, 3); };
  for (std::size_t r = 0; r < ranks; ++r) {
    compute_sum += compute(r);
    if (compute(r) > compute(slow)) slow = r;
    if (at(r, 2) > at(waits, 2)) waits = r;
  }
  const double mean = compute_sum / double(ranks);
  line += fmt::format(
      "slowest rank: {} computes {:.4f} ms per step, {:.2f}x the ranks' mean; rank {} spends most in "
      "communication, {:.4f} ms per step\n",
      slow, compute(slow) * ms, mean > 0 ? compute(slow) / mean : 1.0, waits, at(waits, 2) * ms);
  return line;
}

}  // namespace basalt::run
