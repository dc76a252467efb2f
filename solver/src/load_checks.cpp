// Derived quantities checked at load (masses, springs, wall steps), and scene parts that match nothing
// in the geometry. See load_checks.hpp.
#include "basalt/solver/scene/load_checks.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/core/sphere_mass.hpp"
#include "basalt/solver/models/registry.hpp"
#include "basalt/solver/parallel/communicator.hpp"

namespace basalt::solver {

namespace {

/// "0, 1, 2" (at most 10, then "...").
std::string list_tags(const std::vector<std::int64_t>& tags) {
  std::string s;
  for (std::size_t k = 0; k < tags.size() && k < 10; ++k) s += fmt::format("{}{}", k ? ", " : "", tags[k]);
  if (tags.size() > 10) s += fmt::format(", ... ({} in all)", tags.size());
  return s.empty() ? "none" : s;
}

/// The scene key holding a model's stiffness (the first key documented as one), "K" by default.
std::string stiffness_key(const ModelEntry& m) {
  for (const auto& k : m.keys)
    if (std::string_view(k.doc).starts_with("stiffness")) return std::string(k.key);
  return "K";
}

double norm(const std::array<double, 3>& v) {
  // Scaled, so that components near the double range do not overflow the sum of squares.
  const double s = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
  if (!(s > 0) || !std::isfinite(s)) return s;
  const double a = v[0] / s, b = v[1] / s, c = v[2] / s;
  return s * std::sqrt(a * a + b * b + c * c);
}

}  // namespace

GeometrySummary summarize_geometry(const Scene& scene, const io::Geometry& g, const std::string& source) {
  GeometrySummary s;
  s.particles = g.size();
  s.has_mass = g.has_mass();
  for (std::size_t i = 0; i < g.size(); ++i) {
    const double r = g.radius[i];
    const double m = g.has_mass() ? g.mass[i] : sphere_mass(scene.density, r);
    if (!(m > 0) || !std::isfinite(m) || !std::isfinite(1 / m)) {
      if (g.has_mass())
        s.mass_error = fmt::format(
            "{}: particle id {} has the mass {}: a mass must be finite and > 0, with a finite inverse",
            source, g.id[i], m);
      else
        s.mass_error = fmt::format(
            "material.density = {} gives particle id {} (radius {}) the mass {} (density x 4/3 pi r^3): a "
            "mass must be finite and > 0, with a finite inverse; give the density in the scene's units ({}, "
            "{}, {})",
            scene.density, g.id[i], r, m, scene.units.length, scene.units.time, scene.units.force);
      return s;
    }
    s.m_min = std::min(s.m_min, m);
    s.m_min_pow = std::min(s.m_min_pow, g.has_mass() ? g.mass[i] : sphere_mass(scene.density, g.radius[i]));
    s.rmin = std::min(s.rmin, r);
    s.rmax = std::max(s.rmax, r);
    s.xmax = std::max(
        {s.xmax, std::abs(g.position[i][0]), std::abs(g.position[i][1]), std::abs(g.position[i][2])});
  }
  s.tags.assign(g.tag.begin(), g.tag.end());
  std::sort(s.tags.begin(), s.tags.end());
  s.tags.erase(std::unique(s.tags.begin(), s.tags.end()), s.tags.end());
  for (const auto& b : g.bonds) s.bond_tags.push_back(b.tag);
  std::sort(s.bond_tags.begin(), s.bond_tags.end());
  s.bond_tags.erase(std::unique(s.bond_tags.begin(), s.bond_tags.end()), s.bond_tags.end());
  return s;
}

namespace {
std::vector<std::int64_t> union_of(const std::vector<std::int64_t>& mine, MPI_Comm comm) {
  int n = static_cast<int>(mine.size()), p = 1;
  MPI_Comm_size(comm, &p);
  std::vector<int> counts(static_cast<std::size_t>(p)), displs(static_cast<std::size_t>(p), 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (std::size_t r = 1; r < counts.size(); ++r) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<std::int64_t> all(static_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(mine.data(), n, MPI_INT64_T, all.data(), counts.data(), displs.data(), MPI_INT64_T, comm);
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  return all;
}
}  // namespace

GeometrySummary merge_summaries(const GeometrySummary& local, MPI_Comm comm) {
  GeometrySummary s = local;
  const Comm c(comm);
  if (c.size() == 1) return s;
  s.mass_error = c.agree_error(local.mass_error);
  s.particles = static_cast<std::size_t>(c.sum(static_cast<long long>(local.particles)));
  s.m_min = c.min(local.m_min);
  s.m_min_pow = c.min(local.m_min_pow);
  s.rmin = c.min(local.rmin);
  s.rmax = c.max(local.rmax);
  s.xmax = c.max(local.xmax);
  s.tags = union_of(local.tags, comm);
  s.bond_tags = union_of(local.bond_tags, comm);
  return s;
}

std::vector<std::string> check_scene_with_geometry(const Scene& scene, const io::Geometry& g,
                                                   const std::string& source) {
  return check_scene_with_summary(scene, summarize_geometry(scene, g, source), source);
}

std::vector<std::string> check_scene_with_summary(const Scene& scene, const GeometrySummary& s,
                                                  const std::string& source) {
  std::vector<std::string> warnings;
  if (s.particles == 0) return warnings;
  if (s.mass_error) throw InputError(*s.mass_error);
  const double m_min = s.m_min, rmin = s.rmin, rmax = s.rmax;
  const std::string mass_source = s.has_mass ? fmt::format("the masses of {}", source)
                                             : fmt::format("material.density = {}", scene.density);
  const double dt = scene.dt;

  // Springs: k dt^2 / m (the step's change of velocity per unit of velocity) and the energy of an
  // overlap of a whole diameter must be numbers, or the first force overflows.
  auto check_spring = [&](const std::string& what, const ModelEntry& model, const std::any& params) {
    const double k = model.max_stiffness(params, rmax);
    const double ratio = k * dt * dt / m_min;
    const double energy = 0.5 * k * (2 * rmax) * (2 * rmax);
    if (std::isfinite(k) && std::isfinite(ratio) && std::isfinite(energy)) return;
    throw InputError(fmt::format(
        "{} (type = \"{}\"), key {}: a spring stiffness k = {:.6g} with run.dt = {} and the smallest mass "
        "{:.6g} ({}) gives k dt^2 / m = {:.6g} and an overlap energy k (2 r_max)^2 / 2 = {:.6g}: not finite, "
        "the forces would overflow at the first step; check {}, run.dt and the masses",
        what, model.name, stiffness_key(model), k, dt, m_min, mass_source, ratio, energy,
        stiffness_key(model)));
  };
  for (const auto* groups : {&scene.bonds, &scene.contacts})
    for (const auto& grp : *groups)
      if (const ModelEntry* m = find_model(grp.model, grp.kind))
        check_spring(fmt::format("interactions \"{}\"", grp.name), *m, grp.params);
  for (std::size_t w = 0; w < scene.walls.size(); ++w)
    if (const ModelEntry* m = find_model(scene.walls[w].model, ModelKind::wall))
      check_spring(fmt::format("walls[{}] (\"{}\")", w, scene.walls[w].name), *m, scene.walls[w].params);

  // Moving walls: a wall that moves more than the smallest radius in one step passes through particles.
  for (std::size_t w = 0; w < scene.walls.size(); ++w) {
    const auto& mo = scene.walls[w].motion;
    if (!mo.moves()) continue;
    const bool constant = mo.type == WallMotion::Type::constant_velocity || mo.type == WallMotion::Type::ramp;
    const bool servo = mo.type == WallMotion::Type::servo;
    const double v = constant ? norm(mo.velocity) : (servo ? mo.servo.max_speed : std::abs(mo.amplitude));
    const double step = v * dt;
    if (std::isfinite(step) && step <= rmin) continue;
    throw InputError(
        fmt::format("walls[{}] (\"{}\") motion.{} = {}: the wall moves at up to {:.6g} {}/{}, {:.6g} {} per "
                    "step of run.dt "
                    "= {}, {} the smallest particle radius {:.6g}: particles would pass through it; give the "
                    "wall's speed "
                    "in {}/{}",
                    w, scene.walls[w].name, constant ? "velocity" : (servo ? "max_speed" : "amplitude"),
                    constant ? fmt::format("[{}, {}, {}]", mo.velocity[0], mo.velocity[1], mo.velocity[2])
                             : fmt::format("{}", servo ? mo.servo.max_speed : mo.amplitude),
                    v, scene.units.length, scene.units.time, step, scene.units.length, dt,
                    std::isfinite(step) ? "more than" : "not finite, against", rmin, scene.units.length,
                    scene.units.time));
  }

  // Scene parts that match nothing: warnings, since a run may use a scene for several geometries.
  const auto& tags = s.tags;
  auto missing = [&](const TagFilter& filter) {
    std::vector<std::int64_t> out;
    for (auto t : filter)
      if (!std::binary_search(tags.begin(), tags.end(), t) &&
          std::find(out.begin(), out.end(), t) == out.end())
        out.push_back(t);
    return out;
  };
  auto warn_tags = [&](const std::string& what, const TagFilter& filter, const char* effect) {
    const auto absent = missing(filter);
    if (absent.empty()) return;
    warnings.push_back(
        fmt::format("{} tags = [{}]: no particle of {} has tag{} {}, so {} (particle tags "
                    "present: {})",
                    what, list_tags(filter), source, absent.size() > 1 ? "s" : "", list_tags(absent), effect,
                    list_tags(tags)));
  };
  for (const auto& grp : scene.bonds)
    warn_tags(fmt::format("interactions \"{}\":", grp.name), grp.tags, "the group takes no bond");
  for (const auto& grp : scene.contacts)
    warn_tags(fmt::format("interactions \"{}\":", grp.name), grp.tags, "the group takes no contact");
  for (std::size_t w = 0; w < scene.walls.size(); ++w)
    warn_tags(fmt::format("walls[{}] (\"{}\"):", w, scene.walls[w].name), scene.walls[w].tags,
              "the wall ignores them");
  for (const auto& b : scene.body_forces)
    warn_tags(fmt::format("body_forces \"{}\":", b.name), b.tags, "the force acts on no particle with it");
  for (const auto& grp : scene.bonds) {
    if (!grp.bond_tag) continue;
    const bool found = std::binary_search(s.bond_tags.begin(), s.bond_tags.end(), *grp.bond_tag);
    if (!found)
      warnings.push_back(
          fmt::format("interactions \"{}\": bond_tag = {}: no bond of {} has that tag, so the "
                      "group takes no bond",
                      grp.name, *grp.bond_tag, source));
  }
  return warnings;
}

double strain_resolution(const GeometrySummary& s, double epsilon) {
  return s.particles == 0 ? 0.0 : epsilon * s.xmax / (2 * s.rmin);
}

std::string check_precision(const GeometrySummary& s, double epsilon, const std::string& precision,
                            const std::string& source) {
  const double res = strain_resolution(s, epsilon);
  if (!(res > kResolutionWarn)) return {};
  const std::string what = fmt::format(
      "{}: coordinates reach |x| = {:.3g} with a smallest radius of {:.3g}: in {} a distance between "
      "particles "
      "there is rounded to a strain of {:.2g} (epsilon |x| / 2 r_min)",
      source, s.xmax, s.rmin, precision, res);
  const std::string remedy =
      precision == "float"
          ? "run in double (--precision double) or mixed (--precision mixed: float offsets from the "
            "geometry's centre), or move the geometry nearer the origin"
      : precision == "mixed"
          ? "run in double (--precision double): in mixed precision |x| is the distance from the geometry's "
            "centre, so it is the geometry's extent that is too large for float"
          : "run in mixed precision (--precision mixed: float offsets from the geometry's centre, which "
            "round "
            "to the geometry's size, not to |x|), or move the geometry nearer the origin";
  if (res > kResolutionRefuse)
    throw InputError(
        fmt::format("{}, above the limit {:g}: contact and bond forces would be mostly rounding; {}", what,
                    kResolutionRefuse, remedy));
  return fmt::format("{}, above {:g}: expect energies off by 1e-3 or more (docs/stability.md); {}", what,
                     kResolutionWarn, remedy);
}

void run_load_checks(const Scene& scene, const GeometrySummary& s, const std::string& source, MPI_Comm comm,
                     double epsilon, const std::string& precision) {
  auto warnings = check_scene_with_summary(scene, s, source);
  if (auto w = check_precision(s, epsilon, precision, source); !w.empty()) warnings.push_back(std::move(w));
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0)
    for (const auto& w : warnings) fmt::print(stderr, "basalt-run: warning: {}\n", w);
}

}  // namespace basalt::solver
