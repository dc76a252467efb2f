#pragma once
// Shared by the solver tests: small geometries, scenes from text, a sink that keeps rows in memory.
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/solver/output/field_sink.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::test {

/// Scene from TOML text; geometry.file is a placeholder (tests pass the geometry in memory).
inline solver::Scene scene_from(const std::string& body) {
  return solver::parse_scene_text("[geometry]\nfile = \"unused.geo\"\n" + body, "test.toml", ".");
}

/// Keeps every row: columns[c] -> values by step.
class MemorySink final : public solver::FieldSink {
 public:
  std::vector<std::string> columns;
  std::vector<std::int64_t> steps;
  std::vector<double> times;
  std::vector<std::vector<std::optional<double>>> rows;
  void begin(const std::vector<std::string>& c) override { columns = c; }
  void row(std::int64_t s, double t, const std::vector<std::optional<double>>& v) override {
    steps.push_back(s);
    times.push_back(t);
    rows.push_back(v);
  }
  void flush() override {}
  std::vector<double> column(std::size_t c) const {
    std::vector<double> out;
    for (const auto& r : rows) out.push_back(r[c].value_or(NAN));
    return out;
  }
};

/// Deterministic value in [-1, 1) from an integer (the same on every rank and every library).
inline double hash_unit(std::uint64_t k) {
  k += 0x9E3779B97F4A7C15ull;
  k = (k ^ (k >> 30)) * 0xBF58476D1CE4E5B9ull;
  k = (k ^ (k >> 27)) * 0x94D049BB133111EBull;
  k ^= k >> 31;
  return double(k >> 11) * 0x1.0p-53 * 2.0 - 1.0;
}

/// The particles of `g` inside [lo, hi)^3 and the bonds between them.
inline io::Geometry sub_cube(const io::Geometry& g, double lo, double hi) {
  io::Geometry out;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const auto& x = g.position[i];
    if (x[0] >= lo && x[0] < hi && x[1] >= lo && x[1] < hi && x[2] >= lo && x[2] < hi)
      out.add_particle(g.id[i], x, g.radius[i], g.tag[i]);
  }
  out.sort_by_id();
  for (const auto& b : g.bonds)
    if (out.index_of(b.a) >= 0 && out.index_of(b.b) >= 0) out.bonds.push_back(b);
  return out;
}

}  // namespace basalt::test
