#include "basalt/io/frame.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <stdexcept>
#include <type_traits>

namespace basalt::io {

namespace {

constexpr std::uint64_t kPieceMagic = 0x42534c5446524d31ULL;  // "BSLTFRM1"
constexpr std::uint64_t kInfoMagic = 0x42534c54494e4631ULL;   // "BSLTINF1"

class Writer {
 public:
  explicit Writer(std::vector<std::byte>& out) : out_(out) { out_.clear(); }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    raw(&v, sizeof(T));
  }
  template <class T>
  void array(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    value<std::uint64_t>(v.size());
    raw(v.data(), v.size() * sizeof(T));
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
  template <class T>
  void array(std::vector<T>& v) {
    const auto n = value<std::uint64_t>();
    if (n > (in_.size() - pos_) / std::max<std::size_t>(sizeof(T), 1))
      throw std::runtime_error(fmt::format("frame: array of {} elements overruns the buffer", n));
    v.resize(n);
    raw(v.data(), n * sizeof(T));
  }
  std::string string() {
    const auto n = value<std::uint64_t>();
    if (n > in_.size() - pos_) throw std::runtime_error("frame: string overruns the buffer");
    std::string s(n, '\0');
    raw(s.data(), n);
    return s;
  }
  bool at_end() const { return pos_ == in_.size(); }

 private:
  void raw(void* p, std::size_t n) {
    if (n > in_.size() - pos_) throw std::runtime_error("frame: buffer too short");
    std::memcpy(p, in_.data() + pos_, n);
    pos_ += n;
  }
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
  walls.clear();
}

void serialize(const FramePiece& p, std::vector<std::byte>& out) {
  Writer w(out);
  w.value(kPieceMagic);
  w.value(p.kinds);
  w.value(p.step);
  w.value(p.time);
  w.value(p.dt);
  w.value(p.source_rank);
  w.array(p.id);
  w.array(p.position);
  w.array(p.velocity);
  w.array(p.radius);
  w.array(p.mass);
  w.array(p.tag);
  w.array(p.bonds);
  w.array(p.bond_rest_length);
  w.array(p.bond_broken);
  w.value<std::uint64_t>(p.walls.size());
  for (const auto& wall : p.walls) {
    w.string(wall.name);
    w.value(wall.position);
    w.value(wall.normal);
    w.value(wall.velocity);
    w.value(wall.force);
  }
  w.array(p.inv_mass);
  w.array(p.position_at_rebuild);
  w.value(p.rebuild_step);
  w.value(p.rebuild_pending);
}

FramePiece deserialize(std::span<const std::byte> bytes) {
  Reader r(bytes);
  if (r.value<std::uint64_t>() != kPieceMagic) throw std::runtime_error("frame: bad magic number");
  FramePiece p;
  p.kinds = r.value<std::uint32_t>();
  p.step = r.value<std::int64_t>();
  p.time = r.value<double>();
  p.dt = r.value<double>();
  p.source_rank = r.value<std::int32_t>();
  r.array(p.id);
  r.array(p.position);
  r.array(p.velocity);
  r.array(p.radius);
  r.array(p.mass);
  r.array(p.tag);
  r.array(p.bonds);
  r.array(p.bond_rest_length);
  r.array(p.bond_broken);
  const auto n_walls = r.value<std::uint64_t>();
  if (n_walls > bytes.size()) throw std::runtime_error("frame: wall count overruns the buffer");
  p.walls.resize(n_walls);
  for (auto& wall : p.walls) {
    wall.name = r.string();
    wall.position = r.value<Vec3>();
    wall.normal = r.value<Vec3>();
    wall.velocity = r.value<Vec3>();
    wall.force = r.value<Vec3>();
  }
  r.array(p.inv_mass);
  r.array(p.position_at_rebuild);
  p.rebuild_step = r.value<std::int64_t>();
  p.rebuild_pending = r.value<std::uint8_t>();
  const std::size_t n = p.id.size();
  if (!p.inv_mass.empty() && p.inv_mass.size() != n)
    throw std::runtime_error("frame: inverse masses differ in length from the particles");
  if (!p.position_at_rebuild.empty() && p.position_at_rebuild.size() != n)
    throw std::runtime_error("frame: positions at rebuild differ in length from the particles");
  if (p.position.size() != n || p.velocity.size() != n || p.radius.size() != n || p.mass.size() != n ||
      p.tag.size() != n)
    throw std::runtime_error("frame: particle arrays differ in length");
  const std::size_t m = p.bonds.size();
  if (p.bond_rest_length.size() != m || p.bond_broken.size() != m)
    throw std::runtime_error("frame: bond arrays differ in length");
  if (!r.at_end()) throw std::runtime_error("frame: trailing bytes after the last array");
  return p;
}

void serialize(const RunInfo& info, std::vector<std::byte>& out) {
  Writer w(out);
  w.value(kInfoMagic);
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

  struct BondRow {
    Bond b;
    double rest;
    std::uint8_t broken;
  };
  std::vector<BondRow> bonds;
  bonds.reserve(m);
  for (const auto& p : pieces)
    for (std::size_t k = 0; k < p.bonds.size(); ++k) {
      Bond b = p.bonds[k];
      if (b.a > b.b) std::swap(b.a, b.b);
      bonds.push_back({b, p.bond_rest_length[k], p.bond_broken[k]});
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
  c.step = step;
  c.time = pieces.front().time;
  c.dt = pieces.front().dt;
  c.scene_text = run.scene_text;
  return c;
}

}  // namespace basalt::io
