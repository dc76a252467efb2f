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

namespace {

/// Frees a vector's memory (clear() keeps the capacity).
template <class V>
void release(V& v) {
  V().swap(v);
}

/// A piece's row: which piece, which index in it.
struct Row {
  std::uint32_t piece;
  std::uint32_t index;
};

/// Joins the pieces; `spend`: empties each piece's column once it is copied into the checkpoint, so
/// the pieces and the checkpoint together hold about one copy of the data plus one column.
Checkpoint assemble_pieces(std::vector<FramePiece>& pieces, const RunInfo& run, bool spend) {
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
  std::vector<std::pair<std::int64_t, Row>> order;
  order.reserve(n);
  for (std::uint32_t k = 0; k < pieces.size(); ++k)
    for (std::uint32_t i = 0; i < pieces[k].size(); ++i) order.push_back({pieces[k].id[i], Row{k, i}});
  std::sort(order.begin(), order.end(), [](const auto& x, const auto& y) {
    return x.first < y.first || (x.first == y.first && std::tie(x.second.piece, x.second.index) <
                                                           std::tie(y.second.piece, y.second.index));
  });
  for (std::size_t i = 1; i < order.size(); ++i)
    if (order[i].first == order[i - 1].first)
      throw std::runtime_error(
          fmt::format("assemble: particle id {} appears twice at step {}", order[i].first, step));

  Checkpoint c;
  auto& g = c.geometry;
  const bool inv = std::all_of(pieces.begin(), pieces.end(),
                               [](const FramePiece& p) { return p.inv_mass.size() == p.size(); }) &&
                   n > 0;
  const bool at_rebuild =
      n > 0 && std::all_of(pieces.begin(), pieces.end(), [&](const FramePiece& p) {
        return p.position_at_rebuild.size() == p.size() && p.rebuild_step == pieces.front().rebuild_step;
      });
  if (at_rebuild) {
    c.rebuild_step = pieces.front().rebuild_step;
    for (const auto& p : pieces) c.rebuild_pending = c.rebuild_pending || p.rebuild_pending != 0;
  }
  // One column at a time, through the order: the piece's column is freed once copied.
  const auto gather = [&](auto column, auto& out) {
    out.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      out[i] = (pieces[order[i].second.piece].*column)[order[i].second.index];
    if (spend)
      for (auto& p : pieces) release(p.*column);
  };
  gather(&FramePiece::id, g.id);
  gather(&FramePiece::position, g.position);
  gather(&FramePiece::radius, g.radius);
  gather(&FramePiece::tag, g.tag);
  gather(&FramePiece::mass, g.mass);
  gather(&FramePiece::velocity, c.velocity);
  if (inv) gather(&FramePiece::inv_mass, c.inv_mass);
  if (at_rebuild) gather(&FramePiece::position_at_rebuild, c.position_at_rebuild);
  // Optional particle fields: every piece names the same ones (the solver's list), in the same order.
  for (const auto& p : pieces)
    if (p.fields.size() != pieces.front().fields.size())
      throw std::runtime_error("assemble: pieces with different particle fields");
  for (std::size_t f = 0; f < pieces.front().fields.size(); ++f) {
    const auto& name = pieces.front().fields[f].first;
    for (const auto& p : pieces)
      if (p.fields[f].first != name)
        throw std::runtime_error(fmt::format("assemble: particle field {} missing from a piece", name));
  }
  for (std::size_t f = 0; f < pieces.front().fields.size(); ++f) {
    std::vector<double> values(n);
    for (std::size_t i = 0; i < n; ++i)
      values[i] = pieces[order[i].second.piece].fields[f].second[order[i].second.index];
    c.particle_fields.emplace_back(pieces.front().fields[f].first, std::move(values));
    if (spend)
      for (auto& p : pieces) release(p.fields[f].second);
  }
  release(order);

  // Bonds sorted by (smaller id, larger id): sort references to them, then copy column by column.
  const auto bond_key = [&](const Row& r) {
    const auto& b = pieces[r.piece].bonds[r.index];
    return std::pair(std::min(b.a, b.b), std::max(b.a, b.b));
  };
  std::vector<Row> bonds;
  bonds.reserve(m);
  for (std::uint32_t k = 0; k < pieces.size(); ++k)
    for (std::uint32_t i = 0; i < pieces[k].bonds.size(); ++i) bonds.push_back({k, i});
  std::sort(bonds.begin(), bonds.end(),
            [&](const Row& x, const Row& y) { return bond_key(x) < bond_key(y); });
  g.bonds.resize(m);
  for (std::size_t j = 0; j < m; ++j) {
    Bond b = pieces[bonds[j].piece].bonds[bonds[j].index];
    if (b.a > b.b) std::swap(b.a, b.b);
    g.bonds[j] = b;
  }
  if (spend)
    for (auto& p : pieces) release(p.bonds);
  const auto gather_bonds = [&](auto column, auto& out) {
    out.resize(m);
    for (std::size_t j = 0; j < m; ++j) out[j] = (pieces[bonds[j].piece].*column)[bonds[j].index];
  };
  gather_bonds(&FramePiece::bond_rest_length, c.bond_rest_length);
  if (spend)
    for (auto& p : pieces) release(p.bond_rest_length);
  gather_bonds(&FramePiece::bond_broken, c.bond_broken);
  // Where broken bonds broke (NaN: not known), one row per broken bond, when any piece knows one.
  const bool with_breaks = std::any_of(pieces.begin(), pieces.end(),
                                       [](const FramePiece& p) { return !p.bond_break_position.empty(); });
  if (with_breaks) {
    // The row of each broken bond among its piece's break positions.
    std::vector<std::vector<std::uint32_t>> nth(pieces.size());
    for (std::size_t k = 0; k < pieces.size(); ++k) {
      const auto& p = pieces[k];
      if (p.bond_break_position.empty()) continue;
      nth[k].resize(p.bond_broken.size());
      for (std::uint32_t i = 0, nb = 0; i < p.bond_broken.size(); ++i)
        if (p.bond_broken[i] != 0) nth[k][i] = nb++;
    }
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t j = 0; j < m; ++j) {
      if (c.bond_broken[j] == 0) continue;
      const auto& [k, i] = bonds[j];
      c.bond_break_position.push_back(pieces[k].bond_break_position.empty()
                                          ? Vec3{nan, nan, nan}
                                          : pieces[k].bond_break_position[nth[k][i]]);
    }
  }
  release(bonds);
  if (spend)
    for (auto& p : pieces) {
      release(p.bond_broken);
      release(p.bond_break_position);
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
  if (spend)
    for (auto& p : pieces) {
      release(p.contact_ids);
      release(p.contact_model);
      release(p.contact_history);
    }
  return c;
}

}  // namespace

Checkpoint assemble(std::vector<FramePiece>& pieces, const RunInfo& run) {
  return assemble_pieces(pieces, run, false);
}

Checkpoint assemble(std::vector<FramePiece>&& pieces, const RunInfo& run) {
  return assemble_pieces(pieces, run, true);
}

}  // namespace basalt::io
