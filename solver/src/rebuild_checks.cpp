// The checks at every neighbour-list rebuild (stability/rebuild_checks.hpp): collisions too short for the
// step (docs/stability.md, "Contact scenes at the extremes": at each rebuild the contact models with a
// closed-form collision, hertz_mindlin pairs and walls, report the collision of fewest steps of dt among the
// contacts touching now and the pairs whose straight paths meet; the critical step of the start assumes
// Hertz contacts at 5 % of the largest radius, and a faster impact overlaps deeper and ends sooner, t_c ~
// v^-1/5, which only the run sees), and the rounding of positions far from the origin.
#include "basalt/solver/stability/rebuild_checks.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string_view>

#include "basalt/solver/scene/load_checks.hpp"

namespace basalt::solver {

template <class Real>
std::optional<std::string> RebuildChecks<Real>::impacts(const State& s, double dt,
                                                        const std::vector<std::int64_t>& fixed_tags,
                                                        bool forced, double dt_critical) {
  bool sees = false;  // (the same on every rank: the scene's models)
  for (const auto& f : s.forces.computes()) sees = sees || f->sees_impacts();
  if (!sees) return std::nullopt;
  CollisionSeen mine;
  for (const auto& f : s.forces.computes())
    if (f->sees_impacts()) mine.merge(f->shortest_collision(s.p, s.forces.walls(), dt, fixed_tags));
  const bool parallel = s.comm.size() > 1;
  const long long above5 = parallel ? s.comm.sum(static_cast<long long>(mine.above5)) : mine.above5;
  const long long above20 = parallel ? s.comm.sum(static_cast<long long>(mine.above20)) : mine.above20;
  const double deepest = parallel ? s.comm.max(mine.deepest) : mine.deepest;
  // The shortest collision's rank (-steps: max_loc finds the largest).
  const auto [least, who] = parallel ? s.comm.max_loc(-mine.steps) : std::pair<double, int>{-mine.steps, 0};
  auto& rep = impacts_;
  ++rep.checks;
  rep.above5 = std::max<std::int64_t>(rep.above5, above5);
  rep.above20 = std::max<std::int64_t>(rep.above20, above20);
  rep.deepest = std::max(rep.deepest, deepest);
  if (above20 > 0 && !rep.deep_warned) {
    rep.deep_warned = true;
    if (s.comm.rank() == 0)
      fmt::print(
          stderr,
          "basalt-run: warning: step {}: {} collision(s) reach overlaps above 20 % of the smaller radius "
          "(deepest {:.3g} %, by Hertz's closed form; {} above 5 %): the grains sink into each other, "
          "beyond the small overlaps Hertz's law is meant for (docs/stability.md, \"Contact scenes at "
          "the extremes\"); a stiffer contact (E) or slower impacts keep them small (said once)\n",
          s.step, above20, 100 * deepest, above5);
  }
  const double steps = -least;
  if (!(steps < rep.shortest.steps) && !(steps < kImpactSteps))
    return std::nullopt;  // (common case: nothing new)
  // The shortest collision's numbers, from its rank to all.
  std::vector<double> v(9, 0.0);
  if (s.comm.rank() == who)
    v = {mine.steps, mine.speed,     mine.overlap,   mine.duration,    mine.ra,
         mine.rb,    double(mine.a), double(mine.b), double(mine.wall)};
  if (parallel) {
    for (auto& x : v) x = s.comm.rank() == who ? x : 0.0;
    s.comm.sum_all(v);
  }
  CollisionSeen c;
  c.steps = v[0], c.speed = v[1], c.overlap = v[2], c.duration = v[3], c.ra = v[4], c.rb = v[5];
  c.a = static_cast<std::int64_t>(v[6]), c.b = static_cast<std::int64_t>(v[7]),
  c.wall = static_cast<int>(v[8]);
  if (c.steps < rep.shortest.steps) rep.shortest = c;
  if (!(c.steps < kImpactSteps)) return std::nullopt;
  if (forced && rep.warned) return std::nullopt;
  const double rsmall = c.wall >= 0 ? c.ra : std::min(c.ra, c.rb);
  const std::string who_text =
      c.wall >= 0 ? fmt::format("particle id {} (radius {:.4g}) and wall \"{}\"", c.a, c.ra,
                                s.forces.walls().spec(static_cast<std::size_t>(c.wall)).name)
                  : fmt::format("particles id {} and id {} (radii {:.4g} and {:.4g})", c.a, c.b, c.ra, c.rb);
  const std::string what = fmt::format(
      "step {}: {} collide at the normal speed {:.4g}: by Hertz's closed form the collision lasts {:.4g} and "
      "its "
      "overlap reaches {:.4g} ({:.3g} % of the smaller radius), {:.3g} steps of dt = {:.6g}, fewer than "
      "{:g}: "
      "so short a collision is not resolved (its restitution and overlap come out wrong; docs/stability.md, "
      "\"Contact scenes at the extremes\"). It needs dt <= {:.4g} ({:g} steps per collision; the critical "
      "step of the start, {:.6g}, assumed overlaps of 5 % of the largest radius)",
      s.step, who_text, c.speed, c.duration, c.overlap, 100 * c.overlap / rsmall, c.steps, dt, kImpactSteps,
      c.duration / kImpactSteps, kImpactSteps, dt_critical);
  if (!forced)
    return what + ": lower dt or the impact speed, or set run.force_dt = true / --force-dt to run anyway";
  rep.warned = true;
  if (s.comm.rank() == 0)
    fmt::print(stderr, "basalt-run: warning: {} (forced: the run goes on; said once)\n", what);
  return std::nullopt;
}

template <class Real>
void RebuildChecks<Real>::far_positions(const State& s) {
  if (far_warned_) return;
  double xmax = 0;
  for (std::size_t i = 0; i < s.p.n_owned; ++i)
    xmax =
        std::max({xmax, std::abs(double(s.p.x[i])), std::abs(double(s.p.y[i])), std::abs(double(s.p.z[i]))});
  xmax = s.comm.max(xmax);
  const double resolution = kEpsilon * xmax / (2 * s.rmin);
  if (!(resolution > kResolutionWarn)) return;
  far_warned_ = true;
  if (s.step == 0) return;  // at the start: the load check has warned (or refused) already
  if (s.comm.rank() == 0)
    fmt::print(
        stderr,
        "basalt-run: warning: step {}: particles have reached |x| = {:.4g} with a smallest radius of {:.4g}: "
        "in {} a distance between particles there is rounded to a strain of {:.2g} (epsilon |x| / 2 "
        "r_min), above {:g}: expect the energy to drift (docs/stability.md, \"Energy drift over 1e7 "
        "steps\"); run in double (--precision double)\n",
        s.step, xmax, s.rmin, s.precision, resolution, kResolutionWarn);
}

template <class Real>
void RebuildChecks<Real>::lost_strain(const State& s) {
  if (strain_warned_ || !(s.rmin > 0)) return;
  double xmax = 0, smax = 0;
  for (std::size_t i = 0; i < s.p.n_owned; ++i)
    xmax =
        std::max({xmax, std::abs(double(s.p.x[i])), std::abs(double(s.p.y[i])), std::abs(double(s.p.z[i]))});
  if (s.comm.size() > 1) xmax = s.comm.max(xmax);
  const double resolution = kEpsilon * xmax / (2 * s.rmin);
  // Below this no strain a scene can resolve (>= 1e-9) is at risk: near the origin the strain passes are
  // skipped (the same on every rank: xmax is global).
  if (!(resolution > kStrainLossWarn * 1e-9)) return;
  for (std::size_t k = 0; k < s.bonds.ia.size(); ++k) {
    const auto i = static_cast<std::size_t>(s.bonds.ia[k]), j = static_cast<std::size_t>(s.bonds.ib[k]);
    const double r0 = double(s.bonds.r0[k]);
    if (!(r0 > 0)) continue;
    const double dx = double(s.p.x[i]) - double(s.p.x[j]), dy = double(s.p.y[i]) - double(s.p.y[j]),
                 dz = double(s.p.z[i]) - double(s.p.z[j]);
    smax = std::max(smax, std::abs(std::sqrt(dx * dx + dy * dy + dz * dz) - r0) / r0);
  }
  // Contacts: a listed pair's overlap over the sum of radii (a granular scene's strains).
  for (const PairList* l : {&s.forces.own_pairs(), &s.forces.ghost_pairs()}) {
    if (l->offset.size() < s.p.n_owned + 1) continue;
    for (std::size_t i = 0; i < s.p.n_owned; ++i)
      for (auto e = l->offset[i]; e < l->offset[i + 1]; ++e) {
        const auto j = static_cast<std::size_t>(l->neigh[e]);
        const double rsum = double(s.p.radius[i]) + double(s.p.radius[j]);
        const double dx = double(s.p.x[i]) - double(s.p.x[j]), dy = double(s.p.y[i]) - double(s.p.y[j]),
                     dz = double(s.p.z[i]) - double(s.p.z[j]);
        const double r = std::sqrt(dx * dx + dy * dy + dz * dz);
        if (r < rsum) smax = std::max(smax, (rsum - r) / rsum);
      }
  }
  if (s.comm.size() > 1) smax = s.comm.max(smax);
  strain_max_ = std::max(strain_max_, smax);
  if (std::getenv("BASALT_DEBUG_STRAIN") && s.comm.rank() == 0)
    fmt::print(stderr, "strain: step {} |x|max {:.4g} resolution {:.3g} largest strain {:.3g} ratio {:.3g}\n",
               s.step, xmax, resolution, strain_max_, resolution / strain_max_);
  if (!(strain_max_ > 0) || !(resolution > kStrainLossWarn * strain_max_)) return;
  strain_warned_ = true;
  if (s.comm.rank() == 0)
    fmt::print(
        stderr,
        "basalt-run: warning: step {}: positions reach |x| = {:.4g} with a smallest radius of {:.4g}: in "
        "{} a distance between particles there is rounded to a strain of {:.2g} (epsilon |x| / 2 r_min), "
        "{:.2g} % of the largest bond or contact strain of this run so far ({:.2g}), above {:g} %: "
        "expect results off by about that fraction (docs/stability.md, \"Coordinates far from the "
        "origin\"); {}\n",
        s.step, xmax, s.rmin, s.precision, resolution, 100 * resolution / strain_max_, strain_max_,
        100 * kStrainLossWarn,
        s.precision == std::string_view("double")
            ? "run in mixed precision (--precision mixed: positions as offsets from the geometry's "
              "centre), or move the geometry nearer the origin"
            : "move the geometry nearer the origin of its frame, or run in double");
}

template class RebuildChecks<double>;
template class RebuildChecks<float>;

}  // namespace basalt::solver
