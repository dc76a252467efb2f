// Packing driver: option checks, the power-law radii, random seeding; then the void filler.
#include "basalt/packer/pack.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "basalt/packer/error.hpp"
#include "basalt/packer/random.hpp"
#include "sphere_grid.hpp"

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
    if (!(o.target_fraction > 0 && o.target_fraction < 0.8))
      throw PackError(fmt::format("target solid fraction must be in (0, 0.8), got {}", o.target_fraction));
  }
  // Void filling grows from the seeds' triangulation: too few seeds leave regions it never reaches.
  if (!(o.seed_fraction >= 0.05 && o.seed_fraction < 0.35))
    throw PackError(fmt::format("seed fraction must be in [0.05, 0.35), got {}", o.seed_fraction));
}

std::vector<double> power_law_radii(double rmin, double rmax, double alpha, double solid_volume,
                                    std::uint64_t seed) {
  // Number of spheres larger than r: N(>r) = C (r^-alpha - rmax^-alpha), rmin <= r <= rmax.
  // Their volume: (4/3) pi C alpha * integral of r^(2 - alpha) dr over [rmin, rmax].
  const double integral = std::abs(alpha - 3) < 1e-12
                              ? std::log(rmax / rmin)
                              : (std::pow(rmax, 3 - alpha) - std::pow(rmin, 3 - alpha)) / (3 - alpha);
  std::vector<double> radii;
  if (rmax == rmin) {
    radii.assign(static_cast<std::size_t>(solid_volume / ball_volume(rmax)), rmax);
    return radii;
  }
  const double c = solid_volume / (4.0 / 3.0 * std::numbers::pi * alpha * integral);
  const double top = std::pow(rmax, -alpha);
  Random rng(seed ^ 0x5eedc0ffee123457ULL);
  // Stratified draws: the k-th largest radius solves N(>r) = k + u, u uniform in [0, 1).
  for (std::size_t k = 0;; ++k) {
    const double r = std::pow(top + (static_cast<double>(k) + rng.uniform()) / c, -1.0 / alpha);
    if (r < rmin) break;
    radii.push_back(std::min(r, rmax));
  }
  return radii;
}

Packing pack(const Volume& volume, const PackOptions& opt) {
  check_options(opt);
  const Bounds b = volume.bounds();
  for (int k = 0; k < 3; ++k)
    if (b.hi[k] - b.lo[k] < 2 * opt.rmin)
      throw PackError(fmt::format("the volume ({}) is too small for one sphere of radius rmin = {}",
                                  volume.description(), opt.rmin));
  Packing out;
  detail::SphereGrid grid(b, opt.rmax);
  Random rng(opt.seed);
  std::vector<double> radii;
  detail::FillContext ctx{volume, opt, grid, out};
  if (opt.exponent) {
    radii =
        power_law_radii(opt.rmin, opt.rmax, *opt.exponent, opt.target_fraction * volume.measure(), opt.seed);
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
  if (out.seeds == 0) {
    // Nothing of the first size fits: is there room for even one sphere of radius rmin?
    out.seeds = seed_randomly(
        volume, opt, 1.0, [&](std::size_t) { return opt.rmin; }, 1, grid, out, rng);
    if (out.seeds == 0)
      throw PackError(fmt::format("the volume ({}) is too small for one sphere of radius rmin = {}",
                                  volume.description(), opt.rmin));
    if (opt.exponent) {  // the small sphere replaces the smallest drawn radius
      radii.pop_back();
      out.requested = radii.size() + 1;
    }
  }
  for (double r : out.radius) ctx.placed_solid += 4.0 / 3.0 * std::numbers::pi * r * r * r;
  detail::fill_voids(ctx);
  out.not_placed = ctx.not_placed;
  if (opt.progress) opt.progress(1.0);
  return out;
}

}  // namespace basalt::packer
