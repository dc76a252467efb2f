#include "basalt/io/frame.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <tuple>
#include <type_traits>

namespace basalt::io {

namespace {

constexpr std::uint64_t kInfoMagic = 0x42534c54494e4632ULL;  // "BSLTINF2"

class Writer {
 public:
  explicit Writer(std::vector<std::byte>& out) : out_(out) { out_.clear(); }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    raw(&v, sizeof(T));
  }
  void string(const std::string& s) {
    value<std::uint64_t>(s.size());
    raw(s.data(), s.size());
  }

 private:
  void raw(const void* p, std::size_t n) {
    if (n == 0) return;
    const std::size_t at = out_.size();
    out_.resize(at + n);
    std::memcpy(out_.data() + at, p, n);
  }
  std::vector<std::byte>& out_;
};

class Reader {
 public:
  explicit Reader(std::span<const std::byte> in) : in_(in) {}
  template <class T>
  T value() {
    T v;
    raw(&v, sizeof(T));
    return v;
  }
  std::string string() {
    const auto n = value<std::uint64_t>();
    if (n > in_.size() - pos_) throw std::runtime_error("frame: string overruns the buffer");
    std::string s(n, '\0');
    raw(s.data(), n);
    return s;
  }
  bool at_end() const { return pos_ == in_.size(); }
  void raw(void* p, std::size_t n) {
    if (n > in_.size() - pos_) throw std::runtime_error("frame: buffer too short");
    std::memcpy(p, in_.data() + pos_, n);
    pos_ += n;
  }

 private:
  std::span<const std::byte> in_;
  std::size_t pos_ = 0;
};

}  // namespace

void FramePiece::clear() {
  id.clear();
  position.clear();
  velocity.clear();
  radius.clear();
  mass.clear();
  tag.clear();
  inv_mass.clear();
  position_at_rebuild.clear();
  bonds.clear();
  bond_rest_length.clear();
  bond_broken.clear();
  bond_break_position.clear();
  contact_ids.clear();
  contact_model.clear();
  contact_history.clear();
  fields.clear();
  walls.clear();
  attributes.clear();
}

FrameHeader PieceSource::header() const {
  const std::size_t n = p_.size();
  if (p_.position.size() != n || p_.velocity.size() != n || p_.radius.size() != n || p_.tag.size() != n)
    throw std::invalid_argument("frame piece: particle arrays differ in length");
  if (!p_.inv_mass.empty() && p_.inv_mass.size() != n)
    throw std::invalid_argument("frame piece: inverse masses differ in length from the particles");
  if (p_.inv_mass.empty() && p_.mass.size() != n)
    throw std::invalid_argument("frame piece: masses differ in length from the particles");
  if (!p_.position_at_rebuild.empty() && p_.position_at_rebuild.size() != n)
    throw std::invalid_argument("frame piece: positions at rebuild differ in length from the particles");
  const std::size_t m = p_.bonds.size();
  if (p_.bond_rest_length.size() != m || p_.bond_broken.size() != m)
    throw std::invalid_argument("frame piece: bond arrays differ in length");
  const auto broken = static_cast<std::size_t>(
      std::count_if(p_.bond_broken.begin(), p_.bond_broken.end(), [](std::uint8_t f) { return f != 0; }));
  if (!p_.bond_break_position.empty() && p_.bond_break_position.size() != broken)
    throw std::invalid_argument("frame piece: break positions differ in number from the broken bonds");
  const std::size_t nc = p_.contact_ids.size();
  if (p_.contact_model.size() != nc || p_.contact_history.size() != nc * p_.contact_width)
    throw std::invalid_argument("frame piece: contact arrays differ in length");
  for (const auto& f : p_.fields)
    if (f.second.size() != n)
      throw std::invalid_argument("frame piece: particle field " + f.first + " of the wrong length");
  FrameHeader h;
  h.kinds = p_.kinds;
  h.step = p_.step;
  h.time = p_.time;
  h.source_rank = p_.source_rank;
  h.particles = n;
  h.bonds = m;
  h.contacts = nc;
  h.contact_width = static_cast<std::uint32_t>(p_.contact_width);
  h.fields = p_.fields.size();
  h.breaks = p_.bond_break_position.size();
  h.inverse_mass = !p_.inv_mass.empty();
  h.with_rebuild = !p_.position_at_rebuild.empty();
  h.rebuild_step = p_.rebuild_step;
  h.rebuild_pending = p_.rebuild_pending != 0;
  return h;
}

void PieceSource::write(FrameWriter& w) const {
  const std::size_t n = p_.size();
  w.column(Column::id, p_.id);
  w.column(Column::tag, p_.tag);
  w.column(Column::radius, p_.radius);
  w.column(Column::mass, w.header().inverse_mass ? p_.inv_mass : p_.mass);
  std::vector<double> c(n);
  const auto component = [&](const std::vector<Vec3>& v, std::size_t d, Column col) {
    for (std::size_t i = 0; i < n; ++i) c[i] = v[i][d];
    w.column(col, c);
  };
  for (std::size_t d = 0; d < 3; ++d) {
    component(p_.position, d, static_cast<Column>(static_cast<int>(Column::x) + d));
    component(p_.velocity, d, static_cast<Column>(static_cast<int>(Column::vx) + d));
    if (w.header().with_rebuild)
      component(p_.position_at_rebuild, d, static_cast<Column>(static_cast<int>(Column::x_rebuild) + d));
  }
  for (std::size_t k = 0; k < p_.bonds.size(); ++k) {
    w.set(Column::bond_a, k, p_.bonds[k].a);
    w.set(Column::bond_b, k, p_.bonds[k].b);
    w.set(Column::bond_group, k, p_.bonds[k].tag);
  }
  w.column(Column::bond_rest_length, p_.bond_rest_length);
  w.column(Column::bond_broken, p_.bond_broken);
  const std::size_t nb = p_.bond_break_position.size();
  std::vector<double> b(nb);
  for (std::size_t d = 0; d < 3; ++d) {
    for (std::size_t k = 0; k < nb; ++k) b[k] = p_.bond_break_position[k][d];
    w.column(static_cast<Column>(static_cast<int>(Column::break_x) + d), b);
  }
  for (std::size_t k = 0; k < p_.contact_ids.size(); ++k) {
    w.set(Column::contact_a, k, p_.contact_ids[k][0]);
    w.set(Column::contact_b, k, p_.contact_ids[k][1]);
  }
  w.column(Column::contact_model, p_.contact_model);
  w.column(Column::contact_history, p_.contact_history);
  for (const auto& wall : p_.walls) w.wall(wall);
  for (const auto& [name, values] : p_.fields) w.field(name, std::span<const double>(values));
  w.attributes(p_.attributes);
}

std::size_t serialize(const FrameSource& source, std::vector<std::byte>& out) {
  FrameWriter w(out, source.header());
  source.write(w);
  return w.finish();
}

void serialize(const FramePiece& piece, std::vector<std::byte>& out) { serialize(PieceSource(piece), out); }

namespace {

/// Reads the columns of a received frame (sizes checked against the buffer beforehand).
class ColumnReader {
 public:
  ColumnReader(std::span<const std::byte> bytes, const wire::Layout& layout)
      : bytes_(bytes), layout_(layout) {}
  template <class T>
  T at(Column c, std::size_t i) const {
    T v;
    std::memcpy(&v, bytes_.data() + layout_.offset[std::size_t(c)] + i * sizeof(T), sizeof(T));
    return v;
  }
  template <class T>
  void all(Column c, std::vector<T>& out) const {
    out.resize(layout_.length[std::size_t(c)]);
    if (!out.empty())
      std::memcpy(out.data(), bytes_.data() + layout_.offset[std::size_t(c)], out.size() * sizeof(T));
  }
  void vec3(Column first, std::vector<Vec3>& out) const {
    const auto n = layout_.length[std::size_t(first)];
    out.resize(n);
    for (std::size_t d = 0; d < 3; ++d) {
      const auto c = static_cast<Column>(static_cast<int>(first) + d);
      for (std::size_t i = 0; i < n; ++i) out[i][d] = at<double>(c, i);
    }
  }

 private:
  std::span<const std::byte> bytes_;
  const wire::Layout& layout_;
};

}  // namespace

FramePiece deserialize(std::span<const std::byte> bytes) {
  wire::Header h;
  if (bytes.size() < sizeof(h)) throw std::runtime_error("frame: buffer too short for its header");
  std::memcpy(&h, bytes.data(), sizeof(h));
  if (h.magic != wire::kFrameMagic) throw std::runtime_error("frame: bad magic number");
  const wire::Layout layout(h);
  if (bytes.size() < layout.walls + sizeof(std::uint64_t))
    throw std::runtime_error(fmt::format("frame: {} particles and {} bonds overrun the buffer of {} bytes",
                                         h.particles, h.bonds, bytes.size()));
  const ColumnReader col(bytes, layout);
  FramePiece p;
  p.kinds = h.kinds;
  p.step = h.step;
  p.time = h.time;
  p.source_rank = h.source_rank;
  p.rebuild_step = h.rebuild_step;
  p.rebuild_pending = h.rebuild_pending != 0 ? 1 : 0;
  col.all(Column::id, p.id);
  col.all(Column::tag, p.tag);
  col.all(Column::radius, p.radius);
  col.vec3(Column::x, p.position);
  col.vec3(Column::vx, p.velocity);
  if (h.flags & wire::kWithRebuild) col.vec3(Column::x_rebuild, p.position_at_rebuild);
  if (h.flags & wire::kInverseMass) {
    col.all(Column::mass, p.inv_mass);
    p.mass.resize(p.inv_mass.size());
    for (std::size_t i = 0; i < p.mass.size(); ++i) p.mass[i] = 1.0 / p.inv_mass[i];
  } else {
    col.all(Column::mass, p.mass);
  }
  const std::size_t m = h.bonds;
  p.bonds.resize(m);
  for (std::size_t k = 0; k < m; ++k)
    p.bonds[k] = {col.at<std::int64_t>(Column::bond_a, k), col.at<std::int64_t>(Column::bond_b, k),
                  col.at<std::int32_t>(Column::bond_group, k)};
  col.all(Column::bond_rest_length, p.bond_rest_length);
  col.all(Column::bond_broken, p.bond_broken);
  col.vec3(Column::break_x, p.bond_break_position);
  if (!p.bond_break_position.empty() &&
      p.bond_break_position.size() !=
          static_cast<std::size_t>(std::count_if(p.bond_broken.begin(), p.bond_broken.end(),
                                                 [](std::uint8_t f) { return f != 0; })))
    throw std::runtime_error("frame: break positions differ in number from the broken bonds");
  p.contact_ids.resize(h.contacts);
  for (std::size_t k = 0; k < h.contacts; ++k)
    p.contact_ids[k] = {col.at<std::int64_t>(Column::contact_a, k),
                        col.at<std::int64_t>(Column::contact_b, k)};
  col.all(Column::contact_model, p.contact_model);
  p.contact_width = h.contact_width;
  col.all(Column::contact_history, p.contact_history);

  Reader r(bytes.subspan(layout.walls));
  const auto n_walls = r.value<std::uint64_t>();
  if (n_walls > bytes.size()) throw std::runtime_error("frame: wall count overruns the buffer");
  p.walls.resize(n_walls);
  for (auto& wall : p.walls) {
    wall.name = r.string();
    wall.position = r.value<Vec3>();
    wall.normal = r.value<Vec3>();
    wall.velocity = r.value<Vec3>();
    wall.force = r.value<Vec3>();
    const auto n_state = r.value<std::uint64_t>();
    if (n_state > bytes.size()) throw std::runtime_error("frame: wall state overruns the buffer");
    wall.motion_state.resize(n_state);
    for (auto& v : wall.motion_state) v = r.value<double>();
  }
  if (h.fields > bytes.size()) throw std::runtime_error("frame: particle field count overruns the buffer");
  p.fields.resize(h.fields);
  for (auto& [name, values] : p.fields) {
    name = r.string();
    if (p.id.size() > (bytes.size() / sizeof(double)))
      throw std::runtime_error("frame: particle field overruns the buffer");
    values.resize(p.id.size());
    r.raw(values.data(), values.size() * sizeof(double));
  }
  if (!r.at_end()) {  // the frame's own attributes (a frame from an older writer ends before them)
    const auto n_attributes = r.value<std::uint64_t>();
    if (n_attributes > bytes.size()) throw std::runtime_error("frame: attribute count overruns the buffer");
    for (std::uint64_t k = 0; k < n_attributes; ++k) {
      auto key = r.string();
      p.attributes[key] = r.string();
    }
  }
  if (!r.at_end()) throw std::runtime_error("frame: trailing bytes after the attributes");
  return p;
}

void serialize(const RunInfo& info, std::vector<std::byte>& out) {
  Writer w(out);
  w.value(kInfoMagic);
  w.value(info.dt);
  w.value(info.box_min);
  w.value(info.box_max);
  w.value(info.periodic);
  w.string(info.units.length);
  w.string(info.units.time);
  w.string(info.units.force);
  w.string(info.units.mass);
  w.value<std::uint64_t>(info.attributes.size());
  for (const auto& [k, v] : info.attributes) {
    w.string(k);
    w.string(v);
  }
  w.string(info.scene_text);
}

RunInfo deserialize_run_info(std::span<const std::byte> bytes) {
  Reader r(bytes);
  if (r.value<std::uint64_t>() != kInfoMagic) throw std::runtime_error("run info: bad magic number");
  RunInfo info;
  info.dt = r.value<double>();
  info.box_min = r.value<Vec3>();
  info.box_max = r.value<Vec3>();
  info.periodic = r.value<std::array<bool, 3>>();
  info.units.length = r.string();
  info.units.time = r.string();
  info.units.force = r.string();
  info.units.mass = r.string();
  const auto n = r.value<std::uint64_t>();
  for (std::uint64_t k = 0; k < n; ++k) {
    auto key = r.string();
    info.attributes[key] = r.string();
  }
  info.scene_text = r.string();
  return info;
}

Checkpoint assemble(std::vector<FramePiece>& pieces, const RunInfo& run) {
  if (pieces.empty()) throw std::runtime_error("assemble: no pieces");
  const auto step = pieces.front().step;
  std::size_t n = 0, m = 0;
  for (const auto& p : pieces) {
    if (p.step != step)
      throw std::runtime_error(fmt::format("assemble: pieces of steps {} and {} mixed", step, p.step));
    n += p.size();
    m += p.bonds.size();
  }
  // Gather (piece, index) and sort by id.
  std::vector<std::pair<std::int64_t, std::pair<std::uint32_t, std::uint32_t>>> order;
  order.reserve(n);
  for (std::uint32_t k = 0; k < pieces.size(); ++k)
    for (std::uint32_t i = 0; i < pieces[k].size(); ++i) order.push_back({pieces[k].id[i], {k, i}});
  std::sort(order.begin(), order.end());
  for (std::size_t i = 1; i < order.size(); ++i)
    if (order[i].first == order[i - 1].first)
      throw std::runtime_error(
          fmt::format("assemble: particle id {} appears twice at step {}", order[i].first, step));

  Checkpoint c;
  auto& g = c.geometry;
  g.id.resize(n);
  g.position.resize(n);
  g.radius.resize(n);
  g.tag.resize(n);
  g.mass.resize(n);
  c.velocity.resize(n);
  const bool inv = std::all_of(pieces.begin(), pieces.end(),
                               [](const FramePiece& p) { return p.inv_mass.size() == p.size(); }) &&
                   n > 0;
  if (inv) c.inv_mass.resize(n);
  const bool at_rebuild =
      n > 0 && std::all_of(pieces.begin(), pieces.end(), [&](const FramePiece& p) {
        return p.position_at_rebuild.size() == p.size() && p.rebuild_step == pieces.front().rebuild_step;
      });
  if (at_rebuild) {
    c.position_at_rebuild.resize(n);
    c.rebuild_step = pieces.front().rebuild_step;
    for (const auto& p : pieces) c.rebuild_pending = c.rebuild_pending || p.rebuild_pending != 0;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto& p = pieces[order[i].second.first];
    const auto j = order[i].second.second;
    g.id[i] = p.id[j];
    g.position[i] = p.position[j];
    g.radius[i] = p.radius[j];
    g.tag[i] = p.tag[j];
    g.mass[i] = p.mass[j];
    c.velocity[i] = p.velocity[j];
    if (inv) c.inv_mass[i] = p.inv_mass[j];
    if (at_rebuild) c.position_at_rebuild[i] = p.position_at_rebuild[j];
  }
  // Optional particle fields: every piece names the same ones (the solver's list), in the same order.
  for (const auto& p : pieces)
    if (p.fields.size() != pieces.front().fields.size())
      throw std::runtime_error("assemble: pieces with different particle fields");
  for (std::size_t f = 0; f < pieces.front().fields.size(); ++f) {
    const auto& name = pieces.front().fields[f].first;
    for (const auto& p : pieces)
      if (p.fields[f].first != name)
        throw std::runtime_error(fmt::format("assemble: particle field {} missing from a piece", name));
    std::vector<double> values(n);
    for (std::size_t i = 0; i < n; ++i)
      values[i] = pieces[order[i].second.first].fields[f].second[order[i].second.second];
    c.particle_fields.emplace_back(name, std::move(values));
  }

  struct BondRow {
    Bond b;
    double rest;
    std::uint8_t broken;
    Vec3 at;  ///< where a broken bond broke (NaN: not known)
  };
  const bool with_breaks = std::any_of(pieces.begin(), pieces.end(),
                                       [](const FramePiece& p) { return !p.bond_break_position.empty(); });
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<BondRow> bonds;
  bonds.reserve(m);
  for (const auto& p : pieces)
    for (std::size_t k = 0, nb = 0; k < p.bonds.size(); ++k) {
      Bond b = p.bonds[k];
      if (b.a > b.b) std::swap(b.a, b.b);
      Vec3 at{nan, nan, nan};
      if (p.bond_broken[k] != 0 && !p.bond_break_position.empty()) at = p.bond_break_position[nb++];
      bonds.push_back({b, p.bond_rest_length[k], p.bond_broken[k], at});
    }
  std::sort(bonds.begin(), bonds.end(), [](const BondRow& x, const BondRow& y) {
    return std::tie(x.b.a, x.b.b) < std::tie(y.b.a, y.b.b);
  });
  g.bonds.reserve(m);
  c.bond_rest_length.reserve(m);
  c.bond_broken.reserve(m);
  for (const auto& row : bonds) {
    g.bonds.push_back(row.b);
    c.bond_rest_length.push_back(row.rest);
    c.bond_broken.push_back(row.broken);
    if (with_breaks && row.broken != 0) c.bond_break_position.push_back(row.at);
  }

  // Contacts sorted by (model, pair), whatever rank listed them.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> contacts;
  for (std::uint32_t k = 0; k < pieces.size(); ++k) {
    const auto& p = pieces[k];
    if (!p.contact_ids.empty() && c.contact_width != 0 && p.contact_width != c.contact_width)
      throw std::runtime_error("assemble: pieces with different contact history widths");
    if (!p.contact_ids.empty()) c.contact_width = p.contact_width;
    for (std::uint32_t i = 0; i < p.contact_ids.size(); ++i) contacts.push_back({k, i});
  }
  const auto contact_key = [&](const std::pair<std::uint32_t, std::uint32_t>& e) {
    const auto& p = pieces[e.first];
    const auto& ids = p.contact_ids[e.second];
    // A pair between two ranks comes from each in its own orientation: the lower id first goes first.
    return std::tuple(p.contact_model[e.second], std::min(ids[0], ids[1]), std::max(ids[0], ids[1]), ids[0]);
  };
  std::sort(contacts.begin(), contacts.end(),
            [&](const auto& x, const auto& y) { return contact_key(x) < contact_key(y); });
  for (const auto& [k, i] : contacts) {
    const auto& p = pieces[k];
    c.contact_ids.push_back(p.contact_ids[i]);
    c.contact_model.push_back(p.contact_model[i]);
    const auto* v = p.contact_history.data() + i * p.contact_width;
    c.contact_history.insert(c.contact_history.end(), v, v + p.contact_width);
  }

  for (const auto& p : pieces)
    if (!p.walls.empty()) {
      c.walls = p.walls;
      break;
    }
  g.box_min = run.box_min;
  g.box_max = run.box_max;
  g.periodic = run.periodic;
  g.units = run.units;
  g.attributes = run.attributes;
  for (const auto& p : pieces)
    for (const auto& [k, v] : p.attributes) g.attributes[k] = v;
  c.step = step;
  c.time = pieces.front().time;
  c.dt = run.dt;
  c.scene_text = run.scene_text;
  return c;
}

}  // namespace basalt::io
