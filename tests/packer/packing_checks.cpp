#include "packing_checks.hpp"

#include <algorithm>
#include <fstream>
#include <numbers>
#include <sstream>

namespace basalt::packer::test {

double worst_overlap(const Packing& p) {
  double worst = -1e300;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
      worst = std::max(worst, p.radius[i] + p.radius[j] - norm(p.centre[i] - p.centre[j]));
  return worst;
}

double worst_protrusion(const Volume& v, const Packing& p) {
  double worst = -1e300;
  for (std::size_t i = 0; i < p.size(); ++i)
    worst = std::max(worst, p.radius[i] - v.signed_distance(p.centre[i]));
  return worst;
}

std::set<std::pair<std::int64_t, std::int64_t>> pairs_within(const Packing& p, double tol) {
  std::set<std::pair<std::int64_t, std::int64_t>> out;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
      if (norm(p.centre[i] - p.centre[j]) - p.radius[i] - p.radius[j] <= tol)
        out.emplace(static_cast<std::int64_t>(i), static_cast<std::int64_t>(j));
  return out;
}

double solid_fraction(const Volume& v, const Packing& p) {
  double s = 0;
  for (double r : p.radius) s += 4.0 / 3.0 * std::numbers::pi * r * r * r;
  return s / v.measure();
}

void write_text(const std::filesystem::path& file, const std::string& text) { std::ofstream(file) << text; }

std::string cube_off(double s, int drop) {
  const int tri[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                          {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  std::ostringstream o;
  o << "OFF\n8 " << 12 - drop << " 0\n";
  const double v[8][3] = {{0, 0, 0}, {s, 0, 0}, {s, s, 0}, {0, s, 0},
                          {0, 0, s}, {s, 0, s}, {s, s, s}, {0, s, s}};
  for (const auto& p : v) o << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
  for (int f = 0; f < 12 - drop; ++f) o << "3 " << tri[f][0] << ' ' << tri[f][1] << ' ' << tri[f][2] << '\n';
  return o.str();
}

}  // namespace basalt::packer::test
