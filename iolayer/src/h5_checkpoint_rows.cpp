// Part-wise reading of basalt-checkpoint files (basalt/io/checkpoint_rows.hpp): the header checked as
// read_checkpoint checks the file's shape, then hyperslabs of rows checked as Checkpoint::validate checks
// them, with the same messages.
#include <fmt/format.h>

#include "basalt/io/checkpoint_rows.hpp"
#include "h5_checkpoint_layout.hpp"

namespace basalt::io {

namespace fs = std::filesystem;

struct CheckpointFile::Impl {
  explicit Impl(const fs::path& f) : r(f) {}
  h5::Reader r;
};

CheckpointHeader header_of(const Checkpoint& c) {
  CheckpointHeader h;
  h.particles = c.size();
  h.bonds = c.geometry.bonds.size();
  h.break_positions = c.bond_break_position.size();
  h.has_break_position = !c.bond_break_position.empty();
  h.contacts = c.contact_ids.size();
  h.has_inverse_mass = !c.inv_mass.empty();
  h.has_position_at_rebuild = !c.position_at_rebuild.empty();
  for (const auto& f : c.particle_fields) h.particle_fields.push_back(f.first);
  auto& run = h.run;
  run.geometry.box_min = c.geometry.box_min;
  run.geometry.box_max = c.geometry.box_max;
  run.geometry.periodic = c.geometry.periodic;
  run.geometry.units = c.geometry.units;
  run.geometry.attributes = c.geometry.attributes;
  run.rebuild_step = c.rebuild_step;
  run.rebuild_pending = c.rebuild_pending;
  run.walls = c.walls;
  run.contact_width = c.contact_width;
  run.step = c.step;
  run.time = c.time;
  run.dt = c.dt;
  run.scene_text = c.scene_text;
  return h;
}

CheckpointFile::CheckpointFile(const fs::path& file) : impl_(std::make_unique<Impl>(file)) {
  const auto& r = impl_->r;
  h5::check_schema(r, h5::kCheckpointSchema, h5::kCheckpointVersion);
  h5::check_complete(r);
  auto& h = header_;
  h5::read_geometry_attributes(r, h5::kRunAttributes, h.run.geometry);

  // The shapes read_checkpoint checks, in its order and with its messages.
  const auto rows = h5::check_layout_rows(r);
  const std::size_t n = rows.particles, m = rows.bonds;
  if (!rows.has_mass && n > 0)
    r.fail("/particles/mass", "missing dataset (a checkpoint stores every particle's mass)");
  const auto vrows = r.rows<double>("/particles/velocity", 3);
  if (vrows != n) r.fail("/particles/velocity", fmt::format("{} rows for {} particles", vrows, n));
  h.has_inverse_mass = r.exists("/particles/inverse_mass");
  if (h.has_inverse_mass) {
    const auto irows = r.rows<double>("/particles/inverse_mass");
    if (irows != n) r.fail("/particles/inverse_mass", fmt::format("{} values for {} particles", irows, n));
  }
  h.has_position_at_rebuild = r.exists("/particles/position_at_rebuild");
  if (h.has_position_at_rebuild) {
    const auto prows = r.rows<double>("/particles/position_at_rebuild", 3);
    if (prows != n)
      r.fail("/particles/position_at_rebuild", fmt::format("{} rows for {} particles", prows, n));
    if (!r.has_attribute("/", "rebuild_step"))
      r.fail(h5::root_attribute("rebuild_step"), "missing (required with /particles/position_at_rebuild)");
    h.run.rebuild_step = r.scalar_attribute<std::int64_t>("/", "rebuild_step");
    h.run.rebuild_pending = r.has_attribute("/", "rebuild_pending") &&
                            r.scalar_attribute<std::uint8_t>("/", "rebuild_pending") != 0;
  }
  for (const auto& name : r.members("/particles")) {
    if (is_fixed_particle_dataset(name)) continue;
    const auto ds = "/particles/" + name;
    if (r.rows<double>(ds) != n) r.fail(ds, fmt::format("expected {} values (one per particle)", n));
    h.particle_fields.push_back(name);
  }
  const auto lrows = r.rows<double>("/bonds/rest_length");
  if (lrows != m) r.fail("/bonds/rest_length", fmt::format("{} values for {} bonds", lrows, m));
  const auto brows = r.rows<std::uint8_t>("/bonds/broken");
  if (brows != m) r.fail("/bonds/broken", fmt::format("{} values for {} bonds", brows, m));
  h.has_break_position = r.exists("/bonds/break_position");
  if (h.has_break_position) h.break_positions = r.rows<double>("/bonds/break_position", 3);
  if (r.exists("/contacts/ids")) {
    const auto nc = r.rows<std::int64_t>("/contacts/ids", 2);
    if (r.rows<std::int32_t>("/contacts/model") != nc)
      r.fail("/contacts/model", fmt::format("expected {} values", nc));
    const auto w = h5::contact_width(r);
    if (r.rows<double>("/contacts/history", w) != nc)
      r.fail("/contacts/history", fmt::format("expected {} rows", nc));
    h.contacts = nc;
    h.run.contact_width = w;
  }
  h.run.walls = h5::read_walls(r);
  h.run.step = r.scalar_attribute<std::int64_t>("/", "step");
  h.run.time = r.scalar_attribute<double>("/", "time");
  h.run.dt = r.scalar_attribute<double>("/", "dt");
  h.run.scene_text = r.string_attribute("/", "scene_text");
  h.particles = n;
  h.bonds = m;
  if (h.has_position_at_rebuild && (h.run.rebuild_step < 0 || h.run.rebuild_step > h.run.step))
    throw FormatError(r.file(), "attribute 'rebuild_step' of /",
                      fmt::format("is {}, expected a step in [0, {}] (the checkpoint's step)",
                                  h.run.rebuild_step, h.run.step));
  h.run.validate_run(r.file());
}

CheckpointFile::~CheckpointFile() = default;

const fs::path& CheckpointFile::path() const { return impl_->r.file(); }

namespace {
void check_range(const h5::Reader& r, const char* group, const char* what, std::size_t begin, std::size_t end,
                 std::size_t rows) {
  if (begin > end || end > rows)
    throw FormatError(r.file(), group, fmt::format("rows {} to {} asked of {} {}", begin, end, rows, what));
}
}  // namespace

void CheckpointFile::read_particles(std::size_t begin, std::size_t end, Checkpoint& c) const {
  const auto& r = impl_->r;
  const auto& h = header_;
  check_range(r, "/particles", "particles", begin, end, h.particles);
  const std::size_t n = end - begin;
  h5::read_particle_rows(r, begin, n, true, c.geometry);
  c.velocity.resize(n);
  r.read_rows_into("/particles/velocity", begin, n, 3, reinterpret_cast<double*>(c.velocity.data()));
  c.inv_mass.resize(h.has_inverse_mass ? n : 0);
  if (h.has_inverse_mass) r.read_rows_into("/particles/inverse_mass", begin, n, 0, c.inv_mass.data());
  c.position_at_rebuild.resize(h.has_position_at_rebuild ? n : 0);
  if (h.has_position_at_rebuild)
    r.read_rows_into("/particles/position_at_rebuild", begin, n, 3,
                     reinterpret_cast<double*>(c.position_at_rebuild.data()));
  c.particle_fields.clear();
  for (const auto& name : h.particle_fields) {
    c.particle_fields.emplace_back(name, std::vector<double>(n));
    r.read_rows_into("/particles/" + name, begin, n, 0, c.particle_fields.back().second.data());
  }
  c.validate_particle_rows(r.file());
}

void CheckpointFile::read_bonds(std::size_t begin, std::size_t end, Checkpoint& c) const {
  const auto& r = impl_->r;
  check_range(r, "/bonds", "bonds", begin, end, header_.bonds);
  const std::size_t m = end - begin;
  c.geometry.bonds = h5::read_bond_rows(r, begin, m);
  c.bond_rest_length.resize(m);
  c.bond_broken.resize(m);
  r.read_rows_into("/bonds/rest_length", begin, m, 0, c.bond_rest_length.data());
  r.read_rows_into("/bonds/broken", begin, m, 0, c.bond_broken.data());
  c.validate_bond_rows(r.file(), begin);
}

void CheckpointFile::read_break_positions(std::size_t begin, std::size_t end, Checkpoint& c) const {
  const auto& r = impl_->r;
  check_range(r, "/bonds/break_position", "break positions", begin, end, header_.break_positions);
  c.bond_break_position.resize(end - begin);
  r.read_rows_into("/bonds/break_position", begin, end - begin, 3,
                   reinterpret_cast<double*>(c.bond_break_position.data()));
  c.validate_break_rows(r.file(), begin);
}

void CheckpointFile::read_contacts(std::size_t begin, std::size_t end, Checkpoint& c) const {
  const auto& r = impl_->r;
  check_range(r, "/contacts", "contacts", begin, end, header_.contacts);
  const std::size_t nc = end - begin, w = header_.run.contact_width;
  c.contact_width = w;
  c.contact_ids.resize(nc);
  c.contact_model.resize(nc);
  c.contact_history.resize(nc * w);
  if (nc) {
    r.read_rows_into("/contacts/ids", begin, nc, 2, c.contact_ids.data()->data());
    r.read_rows_into("/contacts/model", begin, nc, 0, c.contact_model.data());
    r.read_rows_into("/contacts/history", begin, nc, w, c.contact_history.data());
  }
  c.walls = header_.run.walls;  // the wall indices are checked against them
  c.validate_contact_rows(r.file(), begin, nullptr);
}

}  // namespace basalt::io
