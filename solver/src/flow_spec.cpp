#include "basalt/solver/scene/flow_spec.hpp"

#include <fmt/format.h>

namespace basalt::solver {

Region parse_region(TableReader& t) {
  Region r;
  const bool box = t.has("box"), cyl = t.has("cylinder");
  if (box == cyl)
    t.fail_here(
        "give the region as one of box = { min = [x, y, z], max = [x, y, z] } or cylinder = { base = [x, y, "
        "z], axis = [x, y, z], radius = R, length = L }");
  if (box) {
    TableReader b(*t.subtable("box"), t.file(), t.path() + ".box");
    r.lo = b.vec3("min");
    r.hi = b.vec3("max");
    for (std::size_t d = 0; d < 3; ++d)
      if (!(r.hi[d] > r.lo[d]) || !std::isfinite(r.lo[d]) || !std::isfinite(r.hi[d]))
        b.fail("max", fmt::format("must exceed min along every axis (axis {}: min {}, max {})", char('x' + d),
                                  r.lo[d], r.hi[d]));
    b.finish();
    return r;
  }
  r.shape = Region::Shape::cylinder;
  TableReader c(*t.subtable("cylinder"), t.file(), t.path() + ".cylinder");
  r.base = c.vec3("base");
  r.axis = c.vec3_opt("axis").value_or(std::array<double, 3>{0, 0, 1});
  const double n = std::sqrt(r.axis[0] * r.axis[0] + r.axis[1] * r.axis[1] + r.axis[2] * r.axis[2]);
  if (!(n > 0) || !std::isfinite(n)) c.fail("axis", "must be a non-zero, finite vector");
  for (auto& a : r.axis) a /= n;
  r.radius = c.positive("radius");
  r.length = c.positive("length");
  c.finish();
  return r;
}

InsertSpec parse_insert(TableReader& t, double density) {
  InsertSpec s;
  s.name = t.string_or("name", t.path());
  s.region = parse_region(t);
  if (!t.has("radius")) t.fail_here("missing key radius: R, or [rmin, rmax] (uniform between)");
  const auto r = t.number_list("radius");
  if (r.size() != 1 && r.size() != 2)
    t.fail("radius", fmt::format("must be R or [rmin, rmax], got {} numbers", r.size()));
  s.rmin = r.front();
  s.rmax = r.back();
  if (!(s.rmin > 0) || !(s.rmax >= s.rmin) || !std::isfinite(s.rmax))
    t.fail("radius", fmt::format("needs 0 < rmin <= rmax, got [{}, {}]", s.rmin, s.rmax));
  s.density = t.has("density") ? t.positive("density") : density;
  s.count = t.integer("count");
  // count = 0: no events of its own; it declares a region and radii for a script's insert() calls.
  if (s.count < 0) t.fail("count", fmt::format("must be >= 0, got {}", s.count));
  s.every = t.integer_or("every", 1);
  if (s.every < 1) t.fail("every", fmt::format("must be >= 1, got {}", s.every));
  s.start = t.integer_or("start", 0);
  if (s.start < 0) t.fail("start", fmt::format("must be >= 0, got {}", s.start));
  s.stop = t.integer_or("stop", s.stop);
  if (s.stop <= s.start) t.fail("stop", fmt::format("must exceed start = {}, got {}", s.start, s.stop));
  if (t.has("velocity")) s.velocity = t.vec3("velocity");
  for (const double v : s.velocity)
    if (!std::isfinite(v)) t.fail("velocity", "must be finite");
  const auto tag = t.integer_or("tag", 0);
  if (tag < std::numeric_limits<std::int32_t>::min() || tag > std::numeric_limits<std::int32_t>::max())
    t.fail("tag", fmt::format("{} does not fit a particle tag (32 bits)", tag));
  s.tag = static_cast<std::int32_t>(tag);
  const auto seed = t.integer_or("seed", 1);
  s.seed = static_cast<std::uint64_t>(seed);
  s.attempts = t.integer_or("attempts", 20);
  if (s.attempts < 1) t.fail("attempts", fmt::format("must be >= 1, got {}", s.attempts));
  // A sphere of the largest radius must fit the region.
  const auto& g = s.region;
  const bool fits = g.shape == Region::Shape::box
                        ? (g.hi[0] - g.lo[0] >= 2 * s.rmax && g.hi[1] - g.lo[1] >= 2 * s.rmax &&
                           g.hi[2] - g.lo[2] >= 2 * s.rmax)
                        : (g.radius >= s.rmax && g.length >= 2 * s.rmax);
  if (!fits)
    t.fail("radius",
           fmt::format("a sphere of radius {} does not fit the region (it must lie wholly inside)", s.rmax));
  t.finish();
  return s;
}

DeleteSpec parse_delete(TableReader& t) {
  DeleteSpec s;
  s.name = t.string_or("name", t.path());
  s.region = parse_region(t);
  s.every = t.integer_or("every", 1);
  if (s.every < 1) t.fail("every", fmt::format("must be >= 1, got {}", s.every));
  s.tags = t.integers_or("tags", {});
  t.finish();
  return s;
}

}  // namespace basalt::solver
