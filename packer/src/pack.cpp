// Packing driver: option checks, the power-law radii, random seeding; then the void filler.
#include "basalt/packer/pack.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "basalt/packer/error.hpp"
#include "basalt/packer/random.hpp"
#include "sphere_grid.hpp"
#include "tiles.hpp"

namespace basalt::packer {

namespace {

double ball_volume(double r) { return 4.0 / 3.0 * std::numbers::pi * r * r * r; }

/// Random sequential addition: spheres of the given radii at uniformly random positions, kept when they
/// fit; stops at `fraction` of the volume or after `max_fails` failures in a row. Returns spheres placed.
std::size_t seed_randomly(const Volume& volume, const PackOptions& opt, double fraction,
                          const std::function<double(std::size_t)>& radius_of, std::size_t max_count,
                          detail::SphereGrid& grid, Packing& out, Random& rng) {
  const Bounds b = volume.bounds();
  const double target = fraction * volume.measure();
  const double tol = opt.overlap_tolerance;
  double solid = 0;
  std::size_t placed = 0;
  constexpr int kMaxFails = 2000;
  while (placed < max_count && solid < target) {
    const double r = radius_of(placed);
    bool ok = false;
    for (int attempt = 0; attempt < kMaxFails && !ok; ++attempt) {
      Vec3 c;
      bool room = true;
      for (int k = 0; k < 3; ++k) {
        if (b.hi[k] - b.lo[k] < 2 * r - 2 * tol) room = false;
        c[k] = b.lo[k] + r + (b.hi[k] - b.lo[k] - 2 * r) * rng.uniform();
      }
      if (!room) break;
      if (volume.signed_distance(c) < r - tol) continue;
      if (grid.overlaps(c, r, tol)) continue;
      grid.add(c, r);
      out.centre.push_back(c);
      out.radius.push_back(r);
      solid += ball_volume(r);
      ok = true;
    }
    if (!ok) break;
    ++placed;
  }
  return placed;
}

}  // namespace

void check_options(const PackOptions& o) {
  if (!std::isfinite(o.rmin) || !std::isfinite(o.rmax))
    throw PackError(
        fmt::format("rmin and rmax must be finite numbers (got rmin {}, rmax {})", o.rmin, o.rmax));
  if (!(o.rmin > 0)) throw PackError(fmt::format("rmin must be > 0, got {}", o.rmin));
  if (o.rmin > o.rmax)
    throw PackError(fmt::format("rmin must not exceed rmax (got rmin {} > rmax {})", o.rmin, o.rmax));
  if (!(o.overlap_tolerance >= 0) || !std::isfinite(o.overlap_tolerance) || o.overlap_tolerance >= o.rmin)
    throw PackError(fmt::format("overlap tolerance must be >= 0 and < rmin, got {}", o.overlap_tolerance));
  if (o.exponent) {
    if (!(*o.exponent > 0) || !std::isfinite(*o.exponent))
      throw PackError(fmt::format("power-law exponent must be > 0 (N(>r) ~ r^-alpha), got {}", *o.exponent));
    if (*o.exponent > kMaxExponent)
      throw PackError(fmt::format(
          "power-law exponent {} is beyond the useful range (0, {}]: at exponent A only a share 2^-A of the "
          "spheres is larger than 2 rmin (one in a million at 20), so the packing would be spheres of radius "
          "rmin with no visible power law; for equal spheres give --rmax {}",
          *o.exponent, kMaxExponent, o.rmin));
    if (!(o.target_fraction > 0 && o.target_fraction < 0.8))
      throw PackError(fmt::format("target solid fraction must be in (0, 0.8), got {}", o.target_fraction));
  }
  // Void filling grows from the seeds' triangulation: too few seeds leave regions it never reaches.
  if (!(o.seed_fraction >= 0.05 && o.seed_fraction < 0.35))
    throw PackError(fmt::format("seed fraction must be in [0.05, 0.35), got {}", o.seed_fraction));
}

namespace {

/// log(e^x - 1) for x > 0, without overflow for large x.
double log_expm1(double x) { return x > 30 ? x + std::log1p(-std::exp(-x)) : std::log(std::expm1(x)); }

/// The power law in units of rmax, so that nothing overflows for any exponent: with R = rmax / rmin,
/// L = ln R and x = r / rmax, N(>r) = C' (x^-alpha - 1) and the spheres' volume is
/// (4/3) pi rmax^3 C' alpha I, I = integral of x^(2 - alpha) over [1/R, 1] = expm1((alpha - 3) L) / (alpha -
/// 3). Returns ln I.
double log_volume_integral(double alpha, double L) {
  if (std::abs(alpha - 3) < 1e-12) return std::log(L);
  if (alpha > 3) return log_expm1((alpha - 3) * L) - std::log(alpha - 3);
  return std::log(-std::expm1((alpha - 3) * L)) - std::log(3 - alpha);
}

}  // namespace

std::vector<double> power_law_radii(double rmin, double rmax, double alpha, double solid_volume,
                                    std::uint64_t seed) {
  std::vector<double> radii;
  if (rmax == rmin) {
    radii.assign(static_cast<std::size_t>(solid_volume / ball_volume(rmax)), rmax);
    return radii;
  }
  // The k-th largest radius solves N(>r) = k + u, u uniform in [0, 1) (stratified draws):
  // x^-alpha = 1 + (k + u) / C', C' = S / (alpha I), S = solid_volume / ((4/3) pi rmax^3); so
  // ln x = -log1p((k + u) alpha I / S) / alpha, which neither overflows nor loses the small alphas.
  // (Written as r^-alpha, rmin^-alpha overflowed for alpha ln(1/rmin) > 709: no radius was drawn and
  // the seeding fell back on popping the last radius of an empty list.)
  const double L = std::log(rmax / rmin);
  const double per_count =
      alpha * std::exp(log_volume_integral(alpha, L)) / (solid_volume / ball_volume(rmax));
  Random rng(seed ^ 0x5eedc0ffee123457ULL);
  for (std::size_t k = 0;; ++k) {
    const double log_x = -std::log1p((static_cast<double>(k) + rng.uniform()) * per_count) / alpha;
    if (!(log_x >= -L)) break;  // r < rmin (or not a number: never loop on it)
    radii.push_back(std::min(rmax * std::exp(log_x), rmax));
  }
  return radii;
}

double expected_sphere_count(double measure, const PackOptions& o) {
  const double fraction = o.exponent ? o.target_fraction : 0.72;
  const double alpha = o.exponent ? *o.exponent : kDenseCountExponent;
  const double solid = fraction * measure / ball_volume(o.rmax);
  const double L = std::log(o.rmax / o.rmin);
  if (!(L > 0)) return solid;
  // N(>rmin) = C' expm1(alpha L), C' = S / (alpha I), in logarithms.
  return std::exp(std::log(solid) + log_expm1(alpha * L) - std::log(alpha) - log_volume_integral(alpha, L));
}

LowFractionReport low_fraction_report(const Volume& volume, const PackOptions& o, const Packing& p,
                                      double solid_fraction) {
  const bool dense = !o.exponent || o.fill_after;
  const double aim = dense ? 0.70 : o.target_fraction;
  LowFractionReport rep;
  if (solid_fraction >= 0.85 * aim) return rep;
  rep.far_below = solid_fraction < 0.5 * aim;
  const Bounds b = volume.bounds();
  const double narrowest = std::min({b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2]});
  const double across = narrowest / (2 * o.rmax);
  const double ratio = o.rmax / o.rmin;
  std::vector<std::string> why;
  if (across < 8)
    why.push_back(
        fmt::format("the volume is only {:.3g} spheres of radius rmax across at its narrowest, and the "
                    "layer next to a wall is about 0.5 solid (0.70 is for volumes 15 across)",
                    across));
  if (ratio < 2.5)
    why.push_back(
        fmt::format("the radius range is narrow (rmax / rmin = {:.3g}): smaller radii fill the gaps "
                    "between large ones, equal spheres saturate near 0.35",
                    ratio));
  if (o.exponent && p.not_placed > 0)
    why.push_back(fmt::format("{} of the {} radii drawn found no room", p.not_placed, p.requested));
  if (why.empty()) why.push_back("none of the known limits applies: please report the command line");
  std::string reasons;
  for (std::size_t i = 0; i < why.size(); ++i) reasons += (i ? "; " : "") + why[i];
  rep.text = fmt::format(
      "solid fraction {:.3f} is {}below the {}'s {:.2f}{}: {}", solid_fraction, rep.far_below ? "far " : "",
      dense ? "dense mode" : "power-law target", aim,
      dense ? fmt::format(" although no room is left for another sphere of radius rmin = {} (2000 random "
                          "probes in a row found none)",
                          o.rmin)
            : "",
      reasons);
  return rep;
}

namespace detail {

Packing pack_part(const Volume& volume, const PackOptions& opt, const PartSpec& part) {
  const Bounds b = volume.bounds();
  Packing out;
  detail::SphereGrid grid(b, opt.rmax);
  // Obstacles placed before (a tile's neighbours): first in `out`, in the grid and the triangulation, and
  // removed again at the end.
  const std::size_t fixed = part.fixed ? part.fixed->size() : 0;
  if (fixed) {
    out.centre = part.fixed->centre;
    out.radius = part.fixed->radius;
    for (std::size_t i = 0; i < fixed; ++i) grid.add(out.centre[i], out.radius[i]);
  }
  Random rng(part.seed);
  std::vector<double> radii;
  detail::FillContext ctx{volume, opt, grid, out};
  ctx.rng = &rng;
  ctx.centre_range = part.centre_range;
  if (part.stage == PartSpec::kFill) {
    ctx.expected_solid = std::max(0.7 - opt.target_fraction, 0.05) * volume.measure();
  } else if (opt.exponent) {
    radii =
        power_law_radii(opt.rmin, opt.rmax, *opt.exponent, opt.target_fraction * volume.measure(), part.seed);
    out.requested = radii.size();
    ctx.radii = &radii;
    out.seeds = seed_randomly(
        volume, opt, opt.seed_fraction, [&](std::size_t i) { return radii[i]; }, radii.size(), grid, out,
        rng);
    ctx.next = out.seeds;
    ctx.expected_solid = opt.target_fraction * volume.measure();
  } else {
    out.seeds = seed_randomly(
        volume, opt, opt.seed_fraction, [&](std::size_t) { return opt.rmax; }, static_cast<std::size_t>(-1),
        grid, out, rng);
    ctx.expected_solid = 0.7 * volume.measure();
  }
  if (out.seeds == 0 && part.stage != PartSpec::kFill) {
    // Nothing of the first size fits: is there room for even one sphere of radius rmin?
    out.seeds = seed_randomly(
        volume, opt, 1.0, [&](std::size_t) { return opt.rmin; }, 1, grid, out, rng);
    if (out.seeds == 0 && fixed == 0)
      throw PackError(fmt::format("the volume ({}) is too small for one sphere of radius rmin = {}",
                                  volume.description(), opt.rmin));
    if (opt.exponent && out.seeds > 0) {  // the small sphere replaces the smallest drawn radius (if any)
      if (!radii.empty()) radii.pop_back();
      out.requested = radii.size() + 1;
    }
  }
  for (std::size_t i = fixed; i < out.size(); ++i)
    ctx.placed_solid += 4.0 / 3.0 * std::numbers::pi * out.radius[i] * out.radius[i] * out.radius[i];
  detail::fill_voids(ctx);
  out.not_placed = ctx.not_placed;
  if (fixed) {
    out.centre.erase(out.centre.begin(), out.centre.begin() + static_cast<std::ptrdiff_t>(fixed));
    out.radius.erase(out.radius.begin(), out.radius.begin() + static_cast<std::ptrdiff_t>(fixed));
  }
  out.centre.shrink_to_fit();
  out.radius.shrink_to_fit();
  return out;
}

}  // namespace detail

Packing pack(const Volume& volume, const PackOptions& opt) {
  check_options(opt);
  const Bounds b = volume.bounds();
  for (int k = 0; k < 3; ++k)
    if (b.hi[k] - b.lo[k] < 2 * opt.rmin)
      throw PackError(fmt::format("the volume ({}) is too small for one sphere of radius rmin = {}",
                                  volume.description(), opt.rmin));
  Packing out;
  if (const auto layout = detail::tile_layout(volume, opt); layout.count() > 1) {
    out = detail::pack_tiles(volume, opt, layout);
  } else {
    detail::PartSpec whole;
    whole.seed = opt.seed;
    out = detail::pack_part(volume, opt, whole);
  }
  if (opt.progress) opt.progress(1.0);
  return out;
}

}  // namespace basalt::packer
