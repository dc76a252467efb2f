// Checkpoints in HDF5, schema "basalt-checkpoint" version 1 (docs/formats.md): the geometry
// layout plus velocities, bond state, walls and the run's clock, marked complete when written.
#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <string_view>
#include <type_traits>
#include <utility>

#include "basalt/io/checkpoint.hpp"
#include "geometry_order.hpp"
#include "h5_checkpoint_layout.hpp"

namespace basalt::io {

namespace fs = std::filesystem;

namespace {

constexpr const char* kWallVectors[] = {"position", "normal", "velocity", "force"};

Vec3& wall_vector(WallState& w, int k) {
  Vec3* v[] = {&w.position, &w.normal, &w.velocity, &w.force};
  return *v[k];
}
const Vec3& wall_vector(const WallState& w, int k) { return wall_vector(const_cast<WallState&>(w), k); }

/// Writes `c` (validated, in file order); see below.
void write_checkpoint_file(const Checkpoint& c, const fs::path& file, Compression compression,
                           const h5::Written& written);

}  // namespace

namespace h5 {

void check_complete(const Reader& r) {
  if (!r.has_attribute("/", "complete"))
    r.fail(root_attribute("complete"),
           "missing: the checkpoint was not completely written (did the run stop while writing it?)");
  const auto mark = r.scalar_attribute<std::int64_t>("/", "complete");
  if (mark != 1)
    r.fail(root_attribute("complete"), fmt::format("is {}, expected 1: the checkpoint is incomplete", mark));
}

std::vector<WallState> read_walls(const Reader& r) {
  const auto names = r.members("/walls");
  std::vector<WallState> walls(names.size());
  std::vector<bool> seen(names.size(), false);
  for (const auto& name : names) {
    const auto g = "/walls/" + name;
    r.require_group(g);
    const auto index = r.scalar_attribute<std::int64_t>(g, "index");
    if (index < 0 || index >= static_cast<std::int64_t>(names.size()) ||
        seen[static_cast<std::size_t>(index)])
      r.fail(fmt::format("attribute 'index' of {}", g),
             fmt::format("{} is not a free position among {} walls", index, names.size()));
    seen[static_cast<std::size_t>(index)] = true;
    WallState& wall = walls[static_cast<std::size_t>(index)];
    wall.name = name;
    for (int k = 0; k < 4; ++k) {
      const auto ds = g + "/" + kWallVectors[k];
      const auto rows = r.rows<double>(ds);
      if (rows != 3) r.fail(ds, fmt::format("expected 3 values, found {}", rows));
      r.read_into(ds, wall_vector(wall, k).data());
    }
    if (r.exists(g + "/motion_state")) wall.motion_state = r.read<double>(g + "/motion_state");
  }
  return walls;
}

std::size_t contact_width(const Reader& r) {
  const auto width = r.scalar_attribute<std::int64_t>("/contacts", "width");
  if (width < 1 || width > 64)
    r.fail("attribute 'width' of /contacts", fmt::format("{} is not in [1, 64]", width));
  return static_cast<std::size_t>(width);
}

}  // namespace h5

Compression parse_compression(const std::string& name) {
  if (name == "none") return Compression::none;
  if (name == "fast") return Compression::fast;
  if (name == "small") return Compression::small;
  throw std::invalid_argument(
      fmt::format("compression \"{}\": expected \"none\", \"fast\" or \"small\"", name));
}

void write_checkpoint(const Checkpoint& c, const fs::path& file, Compression compression) {
  c.validate(file);
  // The file stores particles sorted by id and bonds smaller id first; sort a copy if needed.
  Checkpoint storage;
  const Checkpoint* s = &c;
  if (!in_file_order(c.geometry)) {
    const auto order = sorting_order(c.geometry.id);
    storage = c;
    storage.geometry.sort_by_id();  // the same stable order as `order`
    for (std::size_t k = 0; k < order.size(); ++k) storage.velocity[k] = c.velocity[order[k]];
    if (!c.inv_mass.empty())
      for (std::size_t k = 0; k < order.size(); ++k) storage.inv_mass[k] = c.inv_mass[order[k]];
    if (!c.position_at_rebuild.empty())
      for (std::size_t k = 0; k < order.size(); ++k)
        storage.position_at_rebuild[k] = c.position_at_rebuild[order[k]];
    for (std::size_t f = 0; f < c.particle_fields.size(); ++f)
      for (std::size_t k = 0; k < order.size(); ++k)
        storage.particle_fields[f].second[k] = c.particle_fields[f].second[order[k]];
    s = &storage;
  }
  write_checkpoint_file(*s, file, compression, {});
}

namespace {

/// Writes `s` (validated, in file order); `written(dataset)` is called after each particle, bond and
/// contact dataset, so a caller that owns `s` may free that column (write_checkpoint(Checkpoint&&)).
void write_checkpoint_file(const Checkpoint& c, const fs::path& file, Compression compression,
                           const h5::Written& written) {
  const Checkpoint* s = &c;
  const auto done = [&](std::string_view dataset) {
    if (written) written(dataset);
  };
  h5::Writer w(file, file.string() + ".partial");
  w.compress(compression == Compression::fast ? 1 : compression == Compression::small ? 6 : 0);
  h5::write_schema(w, h5::kCheckpointSchema, h5::kCheckpointVersion);
  h5::write_geometry_layout(w, s->geometry, h5::kRunAttributes, written);
  w.dataset("/particles/velocity", reinterpret_cast<const double*>(s->velocity.data()), s->size(), 3);
  done("/particles/velocity");
  if (!s->inv_mass.empty()) {
    w.dataset("/particles/inverse_mass", s->inv_mass);
    done("/particles/inverse_mass");
  }
  if (!s->position_at_rebuild.empty()) {
    w.dataset("/particles/position_at_rebuild",
              reinterpret_cast<const double*>(s->position_at_rebuild.data()), s->size(), 3);
    done("/particles/position_at_rebuild");
    w.scalar_attribute<std::int64_t>("/", "rebuild_step", s->rebuild_step);
    w.scalar_attribute<std::uint8_t>("/", "rebuild_pending", s->rebuild_pending ? 1 : 0);
  }
  for (const auto& [name, values] : s->particle_fields) {
    w.dataset("/particles/" + name, values);
    done("/particles/" + name);
  }
  w.dataset("/bonds/rest_length", s->bond_rest_length);
  done("/bonds/rest_length");
  w.dataset("/bonds/broken", s->bond_broken);
  done("/bonds/broken");
  if (!s->bond_break_position.empty())
    w.dataset("/bonds/break_position", reinterpret_cast<const double*>(s->bond_break_position.data()),
              s->bond_break_position.size(), 3);
  done("/bonds/break_position");
  w.group("/walls");
  for (std::size_t i = 0; i < s->walls.size(); ++i) {
    const auto& wall = s->walls[i];
    const auto g = "/walls/" + wall.name;
    w.group(g);
    w.scalar_attribute<std::int64_t>(g, "index", static_cast<std::int64_t>(i));
    for (int k = 0; k < 4; ++k) w.dataset(g + "/" + kWallVectors[k], wall_vector(wall, k).data(), 3);
    if (!wall.motion_state.empty()) w.dataset(g + "/motion_state", wall.motion_state);
  }
  if (!s->contact_ids.empty()) {
    w.group("/contacts");
    w.scalar_attribute<std::int64_t>("/contacts", "width", static_cast<std::int64_t>(s->contact_width));
    w.dataset("/contacts/ids", s->contact_ids.data()->data(), s->contact_ids.size(), 2);
    w.dataset("/contacts/model", s->contact_model);
    w.dataset("/contacts/history", s->contact_history.data(), s->contact_ids.size(), s->contact_width);
    done("/contacts/history");
  }
  w.scalar_attribute<std::int64_t>("/", "step", s->step);
  w.scalar_attribute<double>("/", "time", s->time);
  w.scalar_attribute<double>("/", "dt", s->dt);
  w.attribute("/", "scene_text", s->scene_text);
  w.scalar_attribute<std::uint8_t>("/", "complete", 1);  // last: its presence means everything above is there
  w.commit();
}

}  // namespace

void write_checkpoint(Checkpoint&& c, const fs::path& file, Compression compression) {
  if (!in_file_order(c.geometry)) return write_checkpoint(std::as_const(c), file, compression);
  c.validate(file);
  // Each column is freed once in the file: the peak is the file's image plus what is left of `c`.
  const auto release = [](auto& v) { std::decay_t<decltype(v)>().swap(v); };
  auto& g = c.geometry;
  write_checkpoint_file(c, file, compression, [&](std::string_view ds) {
    if (ds == "/particles/position")
      release(g.position);
    else if (ds == "/particles/radius")
      release(g.radius);
    else if (ds == "/particles/tag")
      release(g.tag);
    else if (ds == "/particles/mass")
      release(g.mass);
    else if (ds == "/bonds/tag")
      release(g.bonds);
    else if (ds == "/particles/velocity")
      release(c.velocity);
    else if (ds == "/particles/inverse_mass")
      release(c.inv_mass);
    else if (ds == "/particles/position_at_rebuild")
      release(c.position_at_rebuild);
    else if (ds == "/bonds/rest_length")
      release(c.bond_rest_length);
    else if (ds == "/bonds/broken")
      release(c.bond_broken);
    else if (ds == "/bonds/break_position")
      release(c.bond_break_position);
    else if (ds == "/contacts/history") {
      release(c.contact_ids);
      release(c.contact_model);
      release(c.contact_history);
    } else
      for (auto& [name, values] : c.particle_fields)
        if (ds == "/particles/" + name) release(values);
  });
}

namespace {

Checkpoint read_checkpoint_unguarded(const fs::path& file) {
  h5::Reader r(file);
  h5::check_schema(r, h5::kCheckpointSchema, h5::kCheckpointVersion);
  h5::check_complete(r);

  Checkpoint c;
  c.geometry = h5::read_geometry_layout(r, h5::kRunAttributes);
  const std::size_t n = c.size();
  const std::size_t m = c.geometry.bonds.size();
  if (!c.geometry.has_mass() && n > 0)
    r.fail("/particles/mass", "missing dataset (a checkpoint stores every particle's mass)");

  const auto vrows = r.rows<double>("/particles/velocity", 3);
  if (vrows != n) r.fail("/particles/velocity", fmt::format("{} rows for {} particles", vrows, n));
  c.velocity.resize(n);
  if (n) r.read_into("/particles/velocity", reinterpret_cast<double*>(c.velocity.data()));

  if (r.exists("/particles/inverse_mass")) {
    const auto irows = r.rows<double>("/particles/inverse_mass");
    if (irows != n) r.fail("/particles/inverse_mass", fmt::format("{} values for {} particles", irows, n));
    c.inv_mass = r.read<double>("/particles/inverse_mass");
  }
  if (r.exists("/particles/position_at_rebuild")) {
    const auto prows = r.rows<double>("/particles/position_at_rebuild", 3);
    if (prows != n)
      r.fail("/particles/position_at_rebuild", fmt::format("{} rows for {} particles", prows, n));
    if (!r.has_attribute("/", "rebuild_step"))
      r.fail(h5::root_attribute("rebuild_step"), "missing (required with /particles/position_at_rebuild)");
    c.position_at_rebuild.resize(n);
    if (n)
      r.read_into("/particles/position_at_rebuild", reinterpret_cast<double*>(c.position_at_rebuild.data()));
    c.rebuild_step = r.scalar_attribute<std::int64_t>("/", "rebuild_step");
    c.rebuild_pending = r.has_attribute("/", "rebuild_pending") &&
                        r.scalar_attribute<std::uint8_t>("/", "rebuild_pending") != 0;
  }
  for (const auto& name : r.members("/particles")) {
    if (is_fixed_particle_dataset(name)) continue;
    const auto ds = "/particles/" + name;
    if (r.rows<double>(ds) != n) r.fail(ds, fmt::format("expected {} values (one per particle)", n));
    c.particle_fields.emplace_back(name, r.read<double>(ds));
  }
  const auto lrows = r.rows<double>("/bonds/rest_length");
  if (lrows != m) r.fail("/bonds/rest_length", fmt::format("{} values for {} bonds", lrows, m));
  c.bond_rest_length = r.read<double>("/bonds/rest_length");
  const auto brows = r.rows<std::uint8_t>("/bonds/broken");
  if (brows != m) r.fail("/bonds/broken", fmt::format("{} values for {} bonds", brows, m));
  c.bond_broken = r.read<std::uint8_t>("/bonds/broken");
  if (r.exists("/bonds/break_position")) {
    const auto rows = r.rows<double>("/bonds/break_position", 3);
    c.bond_break_position.resize(rows);
    if (rows) r.read_into("/bonds/break_position", reinterpret_cast<double*>(c.bond_break_position.data()));
  }

  if (r.exists("/contacts/ids")) {
    const auto nc = r.rows<std::int64_t>("/contacts/ids", 2);
    c.contact_ids.resize(nc);
    if (nc) r.read_into("/contacts/ids", c.contact_ids.data()->data());
    if (r.rows<std::int32_t>("/contacts/model") != nc)
      r.fail("/contacts/model", fmt::format("expected {} values", nc));
    c.contact_model = r.read<std::int32_t>("/contacts/model");
    const auto w = h5::contact_width(r);
    if (r.rows<double>("/contacts/history", w) != nc)
      r.fail("/contacts/history", fmt::format("expected {} rows", nc));
    c.contact_width = w;
    c.contact_history = r.read<double>("/contacts/history", w);
  }
  c.walls = h5::read_walls(r);

  c.step = r.scalar_attribute<std::int64_t>("/", "step");
  c.time = r.scalar_attribute<double>("/", "time");
  c.dt = r.scalar_attribute<double>("/", "dt");
  c.scene_text = r.string_attribute("/", "scene_text");
  r.close();
  c.validate(file);
  return c;
}

}  // namespace

Checkpoint read_checkpoint(const fs::path& file) {
  return h5::with_memory_guard(file, [&] { return read_checkpoint_unguarded(file); });
}

bool is_complete_checkpoint(const fs::path& file) {
  try {
    // Opening checks the file is as long as its superblock says (a cut-off file fails here);
    // then the schema, the completion mark, and that every dataset is there with the right shape.
    h5::Reader r(file);
    h5::check_schema(r, h5::kCheckpointSchema, h5::kCheckpointVersion);
    h5::check_complete(r);
    const auto n = r.rows<std::int64_t>("/particles/id");
    const auto m = r.rows<std::int64_t>("/bonds/pairs", 2);
    return r.rows<double>("/particles/position", 3) == n && r.rows<double>("/particles/velocity", 3) == n &&
           r.rows<double>("/particles/radius") == n &&
           ((n == 0 && !r.exists("/particles/mass")) || r.rows<double>("/particles/mass") == n) &&
           r.rows<std::int32_t>("/particles/tag") == n && r.rows<double>("/bonds/rest_length") == m &&
           r.rows<std::uint8_t>("/bonds/broken") == m && r.rows<std::int32_t>("/bonds/tag") == m;
  } catch (const std::exception&) {
    return false;
  }
}

fs::path latest_complete_checkpoint(const fs::path& dir, std::vector<fs::path>* skipped) {
  std::error_code ec;
  std::vector<std::pair<std::int64_t, fs::path>> candidates;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const auto name = it->path().filename().string();
    if (name.size() <= 8 || name.rfind("ckpt_", 0) != 0 || name.substr(name.size() - 3) != ".h5") continue;
    const auto digits = std::string_view(name).substr(5, name.size() - 8);
    if (!std::all_of(digits.begin(), digits.end(), [](char ch) { return ch >= '0' && ch <= '9'; })) continue;
    std::int64_t step = 0;
    auto [p, e] = std::from_chars(digits.data(), digits.data() + digits.size(), step);
    if (e != std::errc() || p != digits.data() + digits.size()) continue;
    candidates.emplace_back(step, it->path());
  }
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second > b.second;
  });
  for (const auto& [step, path] : candidates) {
    if (is_complete_checkpoint(path)) return path;
    if (skipped) skipped->push_back(path);
  }
  return {};
}

}  // namespace basalt::io
