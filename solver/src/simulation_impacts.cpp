// Collisions too short for the step (docs/stability.md, "Contact scenes at the extremes"): at each
// neighbour-list rebuild, the contact models with a closed-form collision (hertz_mindlin, pairs and walls)
// report the collision of fewest steps of dt among the contacts touching now and the pairs whose straight
// paths meet; below kImpactSteps the run stops naming the pair, the impact speed, the overlap and the dt it
// needs. The critical step of the start (simulation_stability.cpp) assumes Hertz contacts at 5 % of the
// largest radius; a faster impact overlaps deeper and ends sooner (t_c ~ v^-1/5), which only the run sees.
#include <fmt/format.h>

#include <cmath>
#include <string>

#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
void Simulation<Real>::check_impacts() {
  bool sees = false;  // (the same on every rank: the scene's models)
  for (const auto& c : forces_.computes()) sees = sees || c->sees_impacts();
  if (!sees) return;
  CollisionSeen mine;
  for (const auto& c : forces_.computes())
    if (c->sees_impacts())
      mine.merge(c->shortest_collision(p_, forces_.walls(), scene_.dt, scene_.fixed_tags));
  const bool parallel = comm().size() > 1;
  const long long above5 = parallel ? comm().sum(static_cast<long long>(mine.above5)) : mine.above5;
  const long long above20 = parallel ? comm().sum(static_cast<long long>(mine.above20)) : mine.above20;
  const double deepest = parallel ? comm().max(mine.deepest) : mine.deepest;
  // The shortest collision's rank (-steps: max_loc finds the largest).
  const auto [least, who] = parallel ? comm().max_loc(-mine.steps) : std::pair<double, int>{-mine.steps, 0};
  auto& rep = impacts_;
  ++rep.checks;
  rep.above5 = std::max<std::int64_t>(rep.above5, above5);
  rep.above20 = std::max<std::int64_t>(rep.above20, above20);
  rep.deepest = std::max(rep.deepest, deepest);
  if (above20 > 0 && !rep.deep_warned) {
    rep.deep_warned = true;
    if (comm().rank() == 0)
      fmt::print(
          stderr,
          "basalt-run: warning: step {}: {} collision(s) reach overlaps above 20 % of the smaller radius "
          "(deepest {:.3g} %, by Hertz's closed form; {} above 5 %): the grains sink into each other, "
          "beyond the small overlaps Hertz's law is meant for (docs/stability.md, \"Contact scenes at "
          "the extremes\"); a stiffer contact (E) or slower impacts keep them small (said once)\n",
          step_, above20, 100 * deepest, above5);
  }
  const double steps = -least;
  if (!(steps < rep.shortest.steps) && !(steps < kImpactSteps)) return;  // (common case: nothing new)
  // The shortest collision's numbers, from its rank to all.
  std::vector<double> v(9, 0.0);
  if (comm().rank() == who)
    v = {mine.steps, mine.speed,     mine.overlap,   mine.duration,    mine.ra,
         mine.rb,    double(mine.a), double(mine.b), double(mine.wall)};
  if (parallel) {
    for (auto& x : v) x = comm().rank() == who ? x : 0.0;
    comm().sum_all(v);
  }
  CollisionSeen s;
  s.steps = v[0], s.speed = v[1], s.overlap = v[2], s.duration = v[3], s.ra = v[4], s.rb = v[5];
  s.a = static_cast<std::int64_t>(v[6]), s.b = static_cast<std::int64_t>(v[7]),
  s.wall = static_cast<int>(v[8]);
  if (s.steps < rep.shortest.steps) rep.shortest = s;
  if (!(s.steps < kImpactSteps)) return;
  const bool forced = scene_.force_dt || options_.force_dt;
  if (forced && rep.warned) return;
  const double rsmall = s.wall >= 0 ? s.ra : std::min(s.ra, s.rb);
  const std::string who_text =
      s.wall >= 0 ? fmt::format("particle id {} (radius {:.4g}) and wall \"{}\"", s.a, s.ra,
                                forces_.walls().spec(static_cast<std::size_t>(s.wall)).name)
                  : fmt::format("particles id {} and id {} (radii {:.4g} and {:.4g})", s.a, s.b, s.ra, s.rb);
  const std::string what = fmt::format(
      "step {}: {} collide at the normal speed {:.4g}: by Hertz's closed form the collision lasts {:.4g} and "
      "its "
      "overlap reaches {:.4g} ({:.3g} % of the smaller radius), {:.3g} steps of dt = {:.6g}, fewer than "
      "{:g}: "
      "so short a collision is not resolved (its restitution and overlap come out wrong; docs/stability.md, "
      "\"Contact scenes at the extremes\"). It needs dt <= {:.4g} ({:g} steps per collision; the critical "
      "step of the start, {:.6g}, assumed overlaps of 5 % of the largest radius)",
      step_, who_text, s.speed, s.duration, s.overlap, 100 * s.overlap / rsmall, s.steps, scene_.dt,
      kImpactSteps, s.duration / kImpactSteps, kImpactSteps, stability_.dt_critical);
  if (!forced)
    stop(what + ": lower dt or the impact speed, or set run.force_dt = true / --force-dt to run anyway");
  rep.warned = true;
  if (comm().rank() == 0)
    fmt::print(stderr, "basalt-run: warning: {} (forced: the run goes on; said once)\n", what);
}

#define BASALT_INSTANTIATE(R) template void Simulation<R>::check_impacts();
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
