// Bonds, region tags, statistics, and the geometry handed to the I/O layer.
#include "basalt/packer/assembly.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <thread>
#include <utility>

#include "basalt/packer/error.hpp"

namespace basalt::packer {

namespace {

/// What the pair search found: bonds (i < j, in order of i then j) and the pair statistics.
struct PairScan {
  std::vector<basalt::io::Bond> bonds;
  std::size_t touching = 0;    ///< pairs with gap <= max_gap
  double largest_overlap = 0;  ///< max over those pairs of -gap (0 when none overlaps)
};

/// Every pair (i < j) with gap <= max_gap, from cell lists in CSR form; bonds are stored only when
/// `keep_bonds`. The index range is cut into chunks of 32 Ki spheres that the threads take in turn;
/// chunks are joined in index order (each freed as it is joined), so the result does not depend on
/// the threads, and no list of all pairs with their gaps is ever held (16 B a pair: 0.5 GB at 8.7 M
/// spheres).
PairScan close_pairs(const std::vector<Vec3>& centre, const std::vector<double>& radius, double max_gap,
                     bool keep_bonds, std::int32_t bond_tag, int threads) {
  const std::size_t n = centre.size();
  PairScan result;
  if (n < 2) return result;
  Vec3 lo = centre[0], hi = centre[0];
  double rmax = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], centre[i][k]);
      hi[k] = std::max(hi[k], centre[i][k]);
    }
    rmax = std::max(rmax, radius[i]);
  }
  const double reach = 2 * rmax + std::max(max_gap, 0.0);
  double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  const double cell = std::max(reach, extent / 512.0);
  int dims[3];
  for (int k = 0; k < 3; ++k) dims[k] = std::max(1, static_cast<int>((hi[k] - lo[k]) / cell) + 1);
  auto coord = [&](double x, int k) { return std::min(dims[k] - 1, static_cast<int>((x - lo[k]) / cell)); };
  auto key = [&](int a, int b, int c) { return (static_cast<std::size_t>(c) * dims[1] + b) * dims[0] + a; };
  const std::size_t ncells = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  std::vector<std::uint32_t> start(ncells + 1, 0), order(n);
  {
    std::vector<std::uint32_t> cell_of(n);  // < 2^32 cells: at most 512^3
    for (std::size_t i = 0; i < n; ++i) {
      cell_of[i] = static_cast<std::uint32_t>(
          key(coord(centre[i][0], 0), coord(centre[i][1], 1), coord(centre[i][2], 2)));
      ++start[cell_of[i] + 1];
    }
    for (std::size_t c = 0; c < ncells; ++c) start[c + 1] += start[c];
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order[fill[cell_of[i]]++] = static_cast<std::uint32_t>(i);
  }
  constexpr std::size_t kChunk = 32768;
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<PairScan> parts(chunks);
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    std::vector<std::pair<std::uint32_t, double>> row;
    for (std::size_t ch = next++; ch < chunks; ch = next++) {
      PairScan& out = parts[ch];
      for (std::size_t i = ch * kChunk; i < std::min(n, (ch + 1) * kChunk); ++i) {
        const int ci[3] = {coord(centre[i][0], 0), coord(centre[i][1], 1), coord(centre[i][2], 2)};
        row.clear();
        for (int c = std::max(0, ci[2] - 1); c <= std::min(dims[2] - 1, ci[2] + 1); ++c)
          for (int b = std::max(0, ci[1] - 1); b <= std::min(dims[1] - 1, ci[1] + 1); ++b)
            for (int a = std::max(0, ci[0] - 1); a <= std::min(dims[0] - 1, ci[0] + 1); ++a) {
              const std::size_t k = key(a, b, c);
              for (std::uint32_t s = start[k]; s < start[k + 1]; ++s) {
                const std::uint32_t j = order[s];
                if (j <= i) continue;
                const double g = norm(centre[i] - centre[j]) - radius[i] - radius[j];
                if (g <= max_gap) row.push_back({j, g});
              }
            }
        std::sort(row.begin(), row.end());
        for (const auto& [j, g] : row) {
          ++out.touching;
          out.largest_overlap = std::max(out.largest_overlap, -g);
          if (keep_bonds)
            out.bonds.push_back({static_cast<std::int64_t>(i), static_cast<std::int64_t>(j), bond_tag});
        }
      }
    }
  };
  threads = std::max(1, std::min<int>(threads, static_cast<int>(chunks)));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& th : pool) th.join();
  std::size_t total = 0;
  for (const auto& p : parts) total += p.bonds.size();
  result.bonds.reserve(total);
  for (auto& p : parts) {
    result.touching += p.touching;
    result.largest_overlap = std::max(result.largest_overlap, p.largest_overlap);
    result.bonds.insert(result.bonds.end(), p.bonds.begin(), p.bonds.end());
    p = PairScan{};
  }
  return result;
}

}  // namespace

TagLayer parse_tag_layer(const std::string& text) {
  const auto bad = [&](const std::string& why) {
    return PackError(
        fmt::format("--tag-layer '{}': {} (expected FACE:THICKNESS:TAG, e.g. zmin:0.5:2)", text, why));
  };
  const auto a = text.find(':');
  const auto b = a == std::string::npos ? a : text.find(':', a + 1);
  if (b == std::string::npos || text.find(':', b + 1) != std::string::npos) throw bad("needs three fields");
  TagLayer layer;
  layer.face = text.substr(0, a);
  const std::string thick = text.substr(a + 1, b - a - 1), tag = text.substr(b + 1);
  auto [p1, e1] = std::from_chars(thick.data(), thick.data() + thick.size(), layer.thickness);
  if (e1 != std::errc() || p1 != thick.data() + thick.size() || !(layer.thickness >= 0))
    throw bad(fmt::format("thickness '{}' is not a number >= 0", thick));
  auto [p2, e2] = std::from_chars(tag.data(), tag.data() + tag.size(), layer.tag);
  if (e2 != std::errc() || p2 != tag.data() + tag.size())
    throw bad(fmt::format("tag '{}' is not an integer", tag));
  if (layer.face.empty()) throw bad("no face");
  return layer;
}

std::vector<std::int32_t> region_tags(const Volume& volume, const std::vector<Vec3>& centre,
                                      const std::vector<double>& radius,
                                      const std::vector<TagLayer>& layers) {
  std::vector<std::int32_t> tags(centre.size(), 0);
  const auto names = volume.piece_names();
  std::vector<BoundaryPiece> pieces;
  for (const auto& layer : layers) {
    int id = -1;
    if (layer.face != "surface") {
      auto it = std::find(names.begin(), names.end(), layer.face);
      if (it == names.end())
        throw PackError(fmt::format("--tag-layer: the volume has no face '{}' (it has: surface, {})",
                                    layer.face, fmt::join(names, ", ")));
      id = static_cast<int>(it - names.begin());
    }
    for (std::size_t i = 0; i < centre.size(); ++i) {
      pieces.clear();
      volume.pieces_near(centre[i], radius[i] + layer.thickness, pieces);
      for (const auto& p : pieces)
        if ((id < 0 || p.id == id) && p.plane.distance(centre[i]) - radius[i] <= layer.thickness) {
          tags[i] = layer.tag;
          break;
        }
    }
  }
  return tags;
}

RadiusHistogram radius_histogram(const std::vector<double>& radius, double rmin, double rmax, int bins) {
  RadiusHistogram h;
  bins = std::max(1, bins);
  const double l0 = std::log(rmin), l1 = std::log(rmax);
  const double width = l1 > l0 ? (l1 - l0) / bins : 1.0;
  for (int k = 0; k <= bins; ++k) h.edges.push_back(std::exp(l0 + width * k));
  h.edges.front() = rmin;
  h.edges.back() = rmax;
  h.counts.assign(bins, 0.0);
  for (double r : radius) {
    int k = l1 > l0 ? static_cast<int>(std::floor((std::log(r) - l0) / width)) : 0;
    h.counts[std::clamp(k, 0, bins - 1)] += 1;
  }
  // Weighted least squares of ln(count) on ln(bin centre), weights = counts.
  double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  int used = 0;
  for (int k = 0; k < bins; ++k) {
    if (h.counts[k] <= 0) continue;
    const double x = l0 + width * (k + 0.5), y = std::log(h.counts[k]), w = h.counts[k];
    sw += w;
    sx += w * x;
    sy += w * y;
    sxx += w * x * x;
    sxy += w * x * y;
    ++used;
  }
  const double den = sw * sxx - sx * sx;
  h.exponent = used >= 2 && den > 0 ? -(sw * sxy - sx * sy) / den : std::numeric_limits<double>::quiet_NaN();
  return h;
}

basalt::io::Geometry assemble(const Volume& volume, const Packing& packing, const PackOptions& popt,
                              const AssemblyOptions& options, AssemblyStats& st) {
  basalt::io::Geometry g;
  const std::size_t n = packing.size();
  const auto tags = region_tags(volume, packing.centre, packing.radius, options.tags);
  g.id.resize(n);
  for (std::size_t i = 0; i < n; ++i) g.id[i] = static_cast<std::int64_t>(i);
  g.position.assign(packing.centre.begin(), packing.centre.end());
  g.radius = packing.radius;
  g.tag = tags;
  // Touching (and bonded, when bonds are on) = gap within the bond tolerance.
  const double bond_tol = options.bond_tolerance;
  auto scan = close_pairs(packing.centre, packing.radius, std::max(bond_tol, 0.0), options.bonds,
                          options.bond_tag, options.threads);
  st = AssemblyStats{};
  st.largest_overlap = scan.largest_overlap;
  const std::size_t touching = scan.touching;
  g.bonds = std::move(scan.bonds);
  const Bounds b = volume.bounds();
  g.box_min = b.lo;
  g.box_max = b.hi;
  double solid = 0;
  st.min_radius = n ? packing.radius[0] : 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = packing.radius[i];
    solid += 4.0 / 3.0 * std::numbers::pi * r * r * r;
    st.largest_boundary_overlap =
        std::max(st.largest_boundary_overlap, r - volume.signed_distance(packing.centre[i]));
    st.min_radius = std::min(st.min_radius, r);
    st.max_radius = std::max(st.max_radius, r);
  }
  st.particles = n;
  st.solid_fraction = solid / volume.measure();
  st.histogram = radius_histogram(packing.radius, popt.rmin, popt.rmax, options.histogram_bins);
  st.bonds = g.bonds.size();
  st.bonds_per_particle = n ? static_cast<double>(st.bonds) / n : 0;
  st.mean_coordination = n ? 2.0 * touching / n : 0;

  auto& s = g.statistics;
  s["particle_count"] = {static_cast<double>(n)};
  s["solid_fraction"] = {st.solid_fraction};
  s["radius_histogram_edges"] = st.histogram.edges;
  s["radius_histogram_counts"] = st.histogram.counts;
  s["power_law_exponent_fitted"] = {st.histogram.exponent};
  if (popt.exponent) s["power_law_exponent_requested"] = {*popt.exponent};
  s["bond_count"] = {static_cast<double>(st.bonds)};
  s["bonds_per_particle"] = {st.bonds_per_particle};
  s["mean_coordination_number"] = {st.mean_coordination};
  s["largest_overlap"] = {st.largest_overlap};
  s["largest_boundary_overlap"] = {std::max(0.0, st.largest_boundary_overlap)};
  s["radius_min_max"] = {st.min_radius, st.max_radius};

  auto& a = g.attributes;
  a["volume"] = volume.description();
  a["volume_measure"] = fmt::format("{:.17g}", volume.measure());
  a["rmin"] = fmt::format("{:.17g}", popt.rmin);
  a["rmax"] = fmt::format("{:.17g}", popt.rmax);
  a["seed"] = fmt::format("{}", popt.seed);
  a["mode"] = popt.exponent ? fmt::format("power-law exponent {:.17g}", *popt.exponent) : "dense";
  a["overlap_tolerance"] = fmt::format("{:.17g}", popt.overlap_tolerance);
  a["bond_tolerance"] = options.bonds ? fmt::format("{:.17g}", options.bond_tolerance) : "none (bonds off)";
  a["bond_rule"] = "bond i-j when |ci - cj| - ri - rj <= bond_tolerance";
  return g;
}

}  // namespace basalt::packer
