#include "basalt/solver/parallel/balance.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace basalt::solver {

std::vector<double> balanced_cuts(const AxisHistogram& h, int parts, double min_width) {
  std::vector<double> cuts;
  if (parts < 2) return cuts;
  const std::size_t bins = h.counts.size();
  const double width = h.hi - h.lo, bin = width / double(bins);
  double total = 0;
  for (const double c : h.counts) total += c;
  std::size_t b = 0;
  double below = 0;  // count in bins [0, b)
  for (int k = 1; k < parts; ++k) {
    if (!(total > 0) || !(width > 0)) {
      cuts.push_back(h.lo + width * k / parts);
      continue;
    }
    const double target = total * k / parts;
    while (b + 1 < bins && below + h.counts[b] < target) below += h.counts[b++];
    const double in_bin = h.counts[b] > 0 ? std::clamp((target - below) / h.counts[b], 0.0, 1.0) : 0.0;
    cuts.push_back(h.lo + (double(b) + in_bin) * bin);
  }
  // Strictly increasing, interior slabs at least min_width wide.
  const double gap = std::max(min_width, 1e-12 * std::max({1.0, std::abs(h.lo), std::abs(h.hi)}));
  // cuts[k - 1] + gap can round so that the difference is an ulp short of gap (seen at -O1 without
  // -march=native): step up until the width, as later code computes it, is at least gap.
  for (std::size_t k = 1; k < cuts.size(); ++k) {
    cuts[k] = std::max(cuts[k], cuts[k - 1] + gap);
    while (cuts[k] - cuts[k - 1] < gap)
      cuts[k] = std::nextafter(cuts[k], std::numeric_limits<double>::infinity());
  }
  return cuts;
}

double largest_slab(const AxisHistogram& h, const std::vector<double>& cuts) {
  std::vector<double> slab(cuts.size() + 1, 0.0);
  const double bin = (h.hi - h.lo) / double(h.counts.size());
  for (std::size_t b = 0; b < h.counts.size(); ++b) {
    const double centre = h.lo + (double(b) + 0.5) * bin;
    slab[static_cast<std::size_t>(std::upper_bound(cuts.begin(), cuts.end(), centre) - cuts.begin())] +=
        h.counts[b];
  }
  return *std::max_element(slab.begin(), slab.end());
}

std::string cuts_text(const std::vector<double>& x, const std::vector<double>& y,
                      const std::vector<double>& z) {
  std::string t;
  for (const auto* axis : {&x, &y, &z}) {
    if (axis != &x) t += ';';
    for (std::size_t k = 0; k < axis->size(); ++k) t += fmt::format("{}{:.17g}", k ? "," : "", (*axis)[k]);
  }
  return t;
}

std::optional<std::array<std::vector<double>, 3>> parse_cuts(const std::string& text) {
  std::array<std::vector<double>, 3> cuts;
  const char* s = text.c_str();
  for (std::size_t d = 0; d < 3; ++d) {
    while (*s != ';' && *s != '\0') {
      char* end = nullptr;
      const double v = std::strtod(s, &end);
      if (end == s || (*end != ',' && *end != ';' && *end != '\0')) return std::nullopt;
      cuts[d].push_back(v);
      s = *end == ',' ? end + 1 : end;
    }
    if (d < 2 && *s++ != ';') return std::nullopt;
  }
  if (*s != '\0') return std::nullopt;
  return cuts;
}

}  // namespace basalt::solver
