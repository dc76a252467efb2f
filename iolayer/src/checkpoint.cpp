// Checkpoint invariants (checkpoint.hpp), independent of the file format.
#include "basalt/io/checkpoint.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <utility>

namespace basalt::io {

bool is_fixed_particle_dataset(const std::string& name) {
  for (const char* fixed :
       {"id", "position", "radius", "tag", "mass", "velocity", "inverse_mass", "position_at_rebuild"})
    if (name == fixed) return true;
  return false;
}

namespace fs = std::filesystem;

namespace {

std::string root_attribute(const char* name) { return fmt::format("attribute '{}' of /", name); }

bool finite(const Vec3& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

}  // namespace

void Checkpoint::validate(const fs::path& source) const {
  geometry.validate(source);
  const std::size_t n = size();
  if (geometry.mass.size() != n)
    throw FormatError(
        source, "/particles/mass",
        fmt::format("a checkpoint stores every mass: {} masses for {} particles", geometry.mass.size(), n));
  validate_particle_rows(source, false);
  if (!position_at_rebuild.empty() && (rebuild_step < 0 || rebuild_step > step))
    throw FormatError(
        source, "attribute 'rebuild_step' of /",
        fmt::format("is {}, expected a step in [0, {}] (the checkpoint's step)", rebuild_step, step));
  validate_bond_rows(source, 0);
  if (!bond_break_position.empty()) {
    const auto broken = static_cast<std::size_t>(
        std::count_if(bond_broken.begin(), bond_broken.end(), [](std::uint8_t f) { return f != 0; }));
    if (bond_break_position.size() != broken)
      throw FormatError(source, "/bonds/break_position", break_rows_text(bond_break_position.size(), broken));
    validate_break_rows(source, 0);
  }
  validate_field_rows(source);
  std::vector<std::int64_t> ids;  // sorted (the particles need not be yet)
  if (!contact_ids.empty()) {
    ids = geometry.id;
    std::sort(ids.begin(), ids.end());
  }
  validate_contact_rows(source, 0, &ids);
  validate_run(source);
}

std::string Checkpoint::break_rows_text(std::size_t rows, std::size_t broken) {
  return fmt::format("{} rows for {} broken bonds (one per bond whose /bonds/broken is not 0)", rows, broken);
}

void Checkpoint::validate_particle_rows(const fs::path& source, bool fields) const {
  const std::size_t n = size();
  if (velocity.size() != n)
    throw FormatError(source, "/particles/velocity",
                      fmt::format("{} velocities for {} particles", velocity.size(), n));
  for (std::size_t i = 0; i < n; ++i)
    if (!finite(velocity[i]))
      throw FormatError(source, "/particles/velocity",
                        fmt::format("particle id {}: velocity is not finite", geometry.id[i]));
  if (!inv_mass.empty() && inv_mass.size() != n)
    throw FormatError(source, "/particles/inverse_mass",
                      fmt::format("{} inverse masses for {} particles", inv_mass.size(), n));
  for (std::size_t i = 0; i < inv_mass.size(); ++i)
    if (!std::isfinite(inv_mass[i]) || inv_mass[i] < 0)
      throw FormatError(source, "/particles/inverse_mass",
                        fmt::format("particle id {}: inverse mass must be finite and >= 0, got {}",
                                    geometry.id[i], inv_mass[i]));
  if (!position_at_rebuild.empty() && position_at_rebuild.size() != n)
    throw FormatError(source, "/particles/position_at_rebuild",
                      fmt::format("{} rows for {} particles", position_at_rebuild.size(), n));
  for (std::size_t i = 0; i < position_at_rebuild.size(); ++i)
    if (!finite(position_at_rebuild[i]))
      throw FormatError(
          source, "/particles/position_at_rebuild",
          fmt::format("particle id {}: position at the last rebuild is not finite", geometry.id[i]));
  if (fields) validate_field_rows(source);
}

void Checkpoint::validate_field_rows(const fs::path& source) const {
  const std::size_t n = size();
  for (const auto& [name, values] : particle_fields) {
    const auto where = "/particles/" + name;
    if (name.empty() || name.find('/') != std::string::npos || name == "." || is_fixed_particle_dataset(name))
      throw FormatError(source, where, "a particle field needs a name of its own, without '/'");
    if (values.size() != n)
      throw FormatError(source, where, fmt::format("{} values for {} particles", values.size(), n));
    for (double v : values)
      if (!std::isfinite(v)) throw FormatError(source, where, "a value is not finite");
  }
}

void Checkpoint::validate_bond_rows(const fs::path& source, std::size_t first) const {
  const std::size_t m = geometry.bonds.size();
  if (bond_rest_length.size() != m)
    throw FormatError(source, "/bonds/rest_length",
                      fmt::format("{} values for {} bonds", bond_rest_length.size(), m));
  if (bond_broken.size() != m)
    throw FormatError(source, "/bonds/broken", fmt::format("{} values for {} bonds", bond_broken.size(), m));
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t k = first + j;
    if (!std::isfinite(bond_rest_length[j]) || bond_rest_length[j] < 0)
      throw FormatError(
          source, "/bonds/rest_length",
          fmt::format("bond {}: rest length must be finite and >= 0, got {}", k, bond_rest_length[j]));
    // Bits 0-1: 0 intact, 1 broken, 2 broke at this step; bits 2-3: the failure mode of a broken bond.
    if ((bond_broken[j] & 3) > 2 || bond_broken[j] > 15 || ((bond_broken[j] & 3) == 0 && bond_broken[j] != 0))
      throw FormatError(
          source, "/bonds/broken",
          fmt::format("bond {}: flag must be 0, or 1 or 2 plus 4 x the failure mode (0-3), got {}", k,
                      bond_broken[j]));
  }
}

void Checkpoint::validate_break_rows(const fs::path& source, std::size_t first) const {
  for (std::size_t j = 0; j < bond_break_position.size(); ++j) {
    const auto& x = bond_break_position[j];
    const bool unknown = std::isnan(x[0]) && std::isnan(x[1]) && std::isnan(x[2]);
    if (!unknown && !finite(x))
      throw FormatError(
          source, "/bonds/break_position",
          fmt::format("row {}: a position must be finite, or NaN in all three (not known)", first + j));
  }
}

void Checkpoint::validate_contact_rows(const fs::path& source, std::size_t first,
                                       const std::vector<std::int64_t>* ids) const {
  const std::size_t nc = contact_ids.size();
  if (contact_model.size() != nc || contact_history.size() != nc * contact_width)
    throw FormatError(source, "/contacts",
                      fmt::format("{} contacts with {} model indices and {} history values ({} per contact)",
                                  nc, contact_model.size(), contact_history.size(), contact_width));
  for (std::size_t j = 0; j < nc; ++j) {
    const std::size_t k = first + j;
    if (contact_model[j] < 0)
      throw FormatError(source, "/contacts/model", fmt::format("contact {}: negative model index", k));
    if (ids && !std::binary_search(ids->begin(), ids->end(), contact_ids[j][0]))
      throw FormatError(source, "/contacts/ids",
                        fmt::format("contact {}: particle id {} does not exist", k, contact_ids[j][0]));
    // The second id is a particle, or a wall as -1 - its index (a particle touching a frictional wall;
    // mesh walls follow the planar ones in the solver's list of walls).
    const auto pid = contact_ids[j][1];
    if (pid < 0 ? (-1 - pid) >= static_cast<std::int64_t>(walls.size())
                : ids && !std::binary_search(ids->begin(), ids->end(), pid))
      throw FormatError(source, "/contacts/ids",
                        fmt::format("contact {}: {} {} does not exist", k, pid < 0 ? "wall" : "particle id",
                                    pid < 0 ? -1 - pid : pid));
  }
  for (double v : contact_history)
    if (!std::isfinite(v)) throw FormatError(source, "/contacts/history", "a history value is not finite");
}

void Checkpoint::validate_run(const fs::path& source) const {
  std::set<std::string> names;
  for (const auto& w : walls) {
    const auto where = "/walls/" + w.name;
    if (w.name.empty() || w.name == "." || w.name.find('/') != std::string::npos)
      throw FormatError(source, where, "a wall name must be non-empty, not '.', and without '/'");
    if (!names.insert(w.name).second) throw FormatError(source, where, "two walls have this name");
    const std::pair<const char*, const Vec3*> vectors[] = {
        {"position", &w.position}, {"normal", &w.normal}, {"velocity", &w.velocity}, {"force", &w.force}};
    for (const auto& [what, v] : vectors)
      if (!finite(*v)) throw FormatError(source, where, fmt::format("{} is not finite", what));
    for (double v : w.motion_state)
      if (!std::isfinite(v)) throw FormatError(source, where + "/motion_state", "a value is not finite");
    const auto& nv = w.normal;
    if (nv[0] == 0 && nv[1] == 0 && nv[2] == 0) throw FormatError(source, where, "normal is the zero vector");
  }
  if (step < 0) throw FormatError(source, root_attribute("step"), fmt::format("must be >= 0, got {}", step));
  if (!std::isfinite(time)) throw FormatError(source, root_attribute("time"), "is not finite");
  if (!std::isfinite(dt) || dt < 0)
    throw FormatError(source, root_attribute("dt"), fmt::format("must be finite and >= 0, got {}", dt));
}

}  // namespace basalt::io
