#pragma once
// Load balancing by a weighted grid (docs/solver.md, "Load balancing"): the rank grid keeps its 3-D
// Cartesian neighbours, and along each axis the dims - 1 cut planes move to where the global particle
// count's marginal along that axis splits evenly. The marginal is a histogram that every rank fills
// with its owned particles and one reduction sums; the cuts below are then a function of that sum
// alone, so every rank computes the same ones. Pure: no MPI (the simulation does the reduction).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace basalt::solver {

/// Counts of coordinates along one axis in `bins` equal bins over [lo, hi] (values outside go to the
/// end bins). Counts are doubles so that one MPI sum adds them exactly (below 2^53 particles).
struct AxisHistogram {
  double lo = 0, hi = 0;
  std::vector<double> counts;

  AxisHistogram(double lo_, double hi_, std::size_t bins) : lo(lo_), hi(hi_), counts(bins, 0.0) {}
  /// Adds one coordinate with a weight (1: a count); integer weights keep the summed histogram exact.
  void add(double v, double weight = 1) {
    const double w = hi - lo;
    const double f = w > 0 ? (v - lo) / w * double(counts.size()) : 0.0;
    const auto b = f <= 0 ? std::size_t(0) : std::min(counts.size() - 1, static_cast<std::size_t>(f));
    counts[b] += weight;
  }
};

/// The particles' extent along each axis (over all ranks) and their marginal histograms along the axes,
/// bins x 3 summed over the ranks (axis d's at [d bins, (d + 1) bins); zeros for an axis not split).
struct BalanceMarginals {
  std::array<double, 3> lo{}, hi{};
  std::vector<double> counts;
};

/// The parts - 1 increasing cut positions that split the histogram's total into `parts` slabs of
/// (nearly) equal count: cut k where the cumulative count reaches k N / parts, linear within its bin,
/// so a slab's count is within one bin's count of N / parts. Interior slabs (1 .. parts - 2) are then
/// widened to at least min_width each (later cuts pushed up: a rank's region must hold its ghost
/// band); the outer slabs are half-infinite and need no width. An empty histogram gives even cuts.
std::vector<double> balanced_cuts(const AxisHistogram& h, int parts, double min_width);

/// run.balance = "time": the weight in the marginal histograms of each particle a rank owns. The rank took
/// work_us microseconds of compute for its n_owned particles, all ranks total_work_us for n_global; a
/// particle weighs its rank's time per particle over the mean time per particle, x 1024, rounded to an
/// integer >= 1 (integers keep the summed histogram exact, so every rank computes the same cuts). No
/// measured time (total_work_us <= 0) weighs every particle alike: the cuts are then those of "count".
inline double time_weight(long long work_us, long long n_owned, long long total_work_us, long long n_global) {
  if (total_work_us <= 0 || n_owned <= 0 || n_global <= 0) return 1024;
  const double per = double(work_us) / double(n_owned), mean = double(total_work_us) / double(n_global);
  return std::max(1.0, std::round(1024 * per / mean));
}

/// The largest slab's count when `cuts` split the histogram (each bin counted in the slab of its centre):
/// how the re-balance judges whether new cuts are worth the migration.
double largest_slab(const AxisHistogram& h, const std::vector<double>& cuts);

/// The cuts as checkpoint text (attribute decomposition_cuts, docs/formats.md): the three axes separated
/// by ';', each axis's cuts by ',', in exact decimal (17 digits), e.g. "1.5,3.25;;" for a 3 x 1 x 1 grid.
std::string cuts_text(const std::vector<double>& x, const std::vector<double>& y,
                      const std::vector<double>& z);
/// Reads cuts_text back; nullopt when the text is not three ';'-separated lists of numbers.
std::optional<std::array<std::vector<double>, 3>> parse_cuts(const std::string& text);

}  // namespace basalt::solver
