#pragma once
// The frame wire format (compute rank -> I/O rank) and the writer that fills it in place.
// A compute rank writes its frame once, straight into the byte buffer that is sent: a fixed
// header, then one column per quantity (structure of arrays, each column 8-byte aligned), then
// the walls. The solver fills the columns from its own arrays through FrameWriter (a memcpy when
// the types match, a converting loop otherwise, e.g. float -> double); the I/O rank reads them
// back with deserialize() (frame.hpp). Header-only: the solver uses it without linking the
// I/O-rank service. Internal to a run: not a file format (checkpoints: docs/formats.md).
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "basalt/io/checkpoint.hpp"

namespace basalt::io {

enum FrameKind : std::uint32_t {
  kFrameCheckpoint = 1u << 0,  ///< write an HDF5 checkpoint of this step
  kFrameVtk = 1u << 1,         ///< write a VTK frame of this step
  kFramePicture = 1u << 2,     ///< draw an in-situ picture of this step (I/O rank 0; pictures.hpp)
};

/// What a frame holds besides its columns' contents: sizes, clock, flags. What is constant for a run
/// (dt, the box, units, the scene) is not in frames: it travels once, in RunInfo (frame.hpp).
struct FrameHeader {
  std::uint32_t kinds = 0;  ///< FrameKind bits
  std::int64_t step = 0;
  double time = 0;
  std::int32_t source_rank = 0;     ///< compute rank that wrote it
  std::uint64_t particles = 0;      ///< length of the particle columns
  std::uint64_t bonds = 0;          ///< length of the bond columns
  std::uint64_t contacts = 0;       ///< length of the contact columns (contacts with a history)
  std::uint32_t contact_width = 0;  ///< float64 values of history per contact
  std::uint64_t fields = 0;         ///< optional particle fields after the walls (FrameWriter::field)
  /// Length of the break-position columns: 0, or one row per broken bond (bond_broken != 0) in the
  /// order of the bond columns (Checkpoint::bond_break_position).
  std::uint64_t breaks = 0;
  /// true: Column::mass holds 1 / mass as the solver holds it (the reader derives the mass, and a
  /// restart gets the same bits); false: it holds the mass and there is no inverse mass.
  bool inverse_mass = true;
  /// true: the columns x_rebuild, y_rebuild, z_rebuild (positions at the last neighbour-list
  /// rebuild, which a restart replays) are present.
  bool with_rebuild = false;
  std::int64_t rebuild_step = -1;
  bool rebuild_pending = false;  ///< the next step rebuilds whatever moved (a bond broke)
};

/// The columns, in wire order. Particle columns have header.particles entries, bond columns
/// header.bonds; the rebuild columns exist only with header.with_rebuild.
enum class Column : std::uint8_t {
  id,
  x,
  y,
  z,
  vx,
  vy,
  vz,
  radius,
  mass,  ///< inverse mass or mass (FrameHeader::inverse_mass)
  tag,
  x_rebuild,
  y_rebuild,
  z_rebuild,
  bond_a,
  bond_b,
  bond_rest_length,
  bond_group,   ///< the bond's tag (the solver's interaction group)
  bond_broken,  ///< 0 or 1
  contact_a,    ///< contact history: the pair (history oriented a -> b)
  contact_b,
  contact_model,    ///< index of the pair model (among those with history)
  contact_history,  ///< contact_width values per contact
  break_x,          ///< where the broken bonds broke (header.breaks rows)
  break_y,
  break_z,
};
inline constexpr std::size_t kColumns = static_cast<std::size_t>(Column::break_z) + 1;

namespace wire {

inline constexpr std::uint64_t kFrameMagic = 0x42534c5446524d36ULL;  // "BSLTFRM6"

/// The header as it travels (all fields 8-byte slots: no padding).
struct Header {
  std::uint64_t magic = kFrameMagic;
  std::uint32_t kinds = 0;
  std::int32_t source_rank = 0;
  std::int64_t step = 0;
  double time = 0;
  std::uint64_t particles = 0;
  std::uint64_t bonds = 0;
  std::uint32_t flags = 0;
  std::uint32_t rebuild_pending = 0;
  std::int64_t rebuild_step = -1;
  std::uint64_t contacts = 0;
  std::uint64_t contact_width = 0;
  std::uint64_t fields = 0;
  std::uint64_t breaks = 0;
};
static_assert(sizeof(Header) == 96 && std::is_trivially_copyable_v<Header>);
inline constexpr std::uint32_t kInverseMass = 1u << 0;
inline constexpr std::uint32_t kWithRebuild = 1u << 1;

enum class Type : std::uint8_t { i64, f64, i32, u8 };

constexpr Type type_of(Column c) {
  switch (c) {
    case Column::id:
    case Column::bond_a:
    case Column::bond_b:
    case Column::contact_a:
    case Column::contact_b:
      return Type::i64;
    case Column::tag:
    case Column::bond_group:
    case Column::contact_model:
      return Type::i32;
    case Column::bond_broken:
      return Type::u8;
    default:
      return Type::f64;
  }
}
constexpr std::size_t size_of(Type t) { return t == Type::u8 ? 1 : t == Type::i32 ? 4 : 8; }
constexpr bool is_bond(Column c) { return c >= Column::bond_a && c <= Column::bond_broken; }
constexpr bool is_contact(Column c) { return c >= Column::contact_a && c <= Column::contact_history; }
constexpr bool is_break(Column c) { return c >= Column::break_x; }
constexpr bool is_rebuild(Column c) { return c >= Column::x_rebuild && c <= Column::z_rebuild; }
constexpr std::size_t align8(std::size_t n) { return (n + 7) & ~std::size_t(7); }

/// Where each column starts and where the walls start, for a header (overflow-checked: the
/// reader computes it from untrusted sizes).
struct Layout {
  std::array<std::size_t, kColumns> offset{};
  std::array<std::size_t, kColumns> length{};  ///< entries (0 for an absent column)
  std::size_t walls = 0;                       ///< offset of the wall count

  explicit Layout(const Header& h) {
    // A frame never comes near 2^40 entries; larger counts are a damaged buffer.
    constexpr std::uint64_t kMax = std::uint64_t(1) << 40;
    if (h.particles > kMax || h.bonds > kMax || h.contacts > kMax || h.contact_width > 64 ||
        h.breaks > h.bonds)
      throw std::runtime_error("frame: impossible particle, bond or contact count");
    std::size_t at = sizeof(Header);
    for (std::size_t k = 0; k < kColumns; ++k) {
      const auto c = static_cast<Column>(k);
      const bool present = !is_rebuild(c) || (h.flags & kWithRebuild);
      length[k] = !present                       ? 0
                  : is_bond(c)                   ? h.bonds
                  : is_break(c)                  ? h.breaks
                  : c == Column::contact_history ? h.contacts * h.contact_width
                  : is_contact(c)                ? h.contacts
                                                 : h.particles;
      offset[k] = at;
      at += align8(length[k] * size_of(type_of(c)));
    }
    walls = at;
  }
};

}  // namespace wire

/// Writes one frame into `out` (resized to the frame's size; a recycled buffer keeps its
/// capacity and is not cleared first, so nothing is written twice). Every column of the header's
/// layout must be filled exactly (finish() checks the counts).
class FrameWriter {
 public:
  FrameWriter(std::vector<std::byte>& out, const FrameHeader& h) : out_(out), layout_(to_wire(h)) {
    out_.resize(layout_.walls + sizeof(std::uint64_t));
    std::memcpy(out_.data(), &wire_, sizeof(wire_));
  }

  const FrameHeader& header() const { return header_; }

  /// Entries [first, first + v.size()) of column `c`, converted to the column's wire type.
  template <class T>
  void column(Column c, std::span<const T> v, std::size_t first = 0) {
    static_assert(std::is_arithmetic_v<T>);
    std::byte* dst = slot(c, first, v.size());
    switch (wire::type_of(c)) {
      case wire::Type::i64:
        return store<std::int64_t>(dst, v.data(), v.size());
      case wire::Type::f64:
        return store<double>(dst, v.data(), v.size());
      case wire::Type::i32:
        return store<std::int32_t>(dst, v.data(), v.size());
      case wire::Type::u8:
        return store<std::uint8_t>(dst, v.data(), v.size());
    }
  }
  template <class T>
  void column(Column c, const std::vector<T>& v, std::size_t first = 0) {
    column(c, std::span<const T>(v), first);
  }
  /// Entries [first, first + count) of column `c` all equal to `value`.
  template <class T>
  void fill(Column c, std::size_t first, std::size_t count, T value) {
    std::byte* dst = slot(c, first, count);
    const auto n = wire::size_of(wire::type_of(c));
    for (std::size_t i = 0; i < count; ++i) put(c, dst + i * n, value);
  }
  /// Entry k of column `c`.
  template <class T>
  void set(Column c, std::size_t k, T value) {
    put(c, slot(c, k, 1), value);
  }
  /// Appends an optional particle field (after every wall): its name and one value per particle,
  /// sent as float64. header.fields of them must follow the walls.
  template <class T>
  void field(std::string_view name, std::span<const T> v) {
    if (attributes_) throw std::logic_error("frame writer: particle fields must come before the attributes");
    if (v.size() != layout_.length[0])
      throw std::logic_error("frame writer: a particle field of the wrong length");
    append(std::uint64_t(name.size()));
    append_raw(name.data(), name.size());
    const std::size_t at = out_.size();
    out_.resize(at + v.size() * sizeof(double));
    store<double>(out_.data() + at, v.data(), v.size());
    ++fields_;
  }
  /// Appends a wall (walls are global: one compute rank's frame carries them).
  void wall(const WallState& w) {
    if (fields_ > 0 || attributes_)
      throw std::logic_error("frame writer: walls must come before the particle fields");
    append(std::uint64_t(w.name.size()));
    append_raw(w.name.data(), w.name.size());
    for (const Vec3* v : {&w.position, &w.normal, &w.velocity, &w.force}) append(*v);
    append(std::uint64_t(w.motion_state.size()));
    for (const double v : w.motion_state) append(v);
    ++walls_;
  }
  /// Appends the frame's own root attributes for a checkpoint (after every particle field; at most
  /// once): global values that change during a run, e.g. the decomposition's cuts, which override
  /// the run's attributes (RunInfo) of the same name. One compute rank's frame carries them.
  void attributes(const std::map<std::string, std::string>& a) {
    if (attributes_) throw std::logic_error("frame writer: attributes written twice");
    attributes_ = true;
    append(std::uint64_t(a.size()));
    for (const auto& [k, v] : a)
      for (const std::string* t : {&k, &v}) {
        append(std::uint64_t(t->size()));
        append_raw(t->data(), t->size());
      }
  }
  /// Checks that every column was filled exactly once over; returns the frame's size in bytes.
  /// Throws std::logic_error otherwise (a bug in the code that fills the frame).
  std::size_t finish() {
    if (!attributes_) attributes({});
    for (std::size_t k = 0; k < kColumns; ++k)
      if (filled_[k] != layout_.length[k])
        throw std::logic_error("frame writer: column " + std::to_string(k) + " filled with " +
                               std::to_string(filled_[k]) + " of " + std::to_string(layout_.length[k]) +
                               " entries");
    if (fields_ != header_.fields)
      throw std::logic_error("frame writer: " + std::to_string(fields_) + " particle fields written, " +
                             std::to_string(header_.fields) + " announced");
    std::memcpy(out_.data() + layout_.walls, &walls_, sizeof(walls_));
    return out_.size();
  }

 private:
  const wire::Header& to_wire(const FrameHeader& h) {
    header_ = h;
    wire_.kinds = h.kinds;
    wire_.source_rank = h.source_rank;
    wire_.step = h.step;
    wire_.time = h.time;
    wire_.particles = h.particles;
    wire_.bonds = h.bonds;
    wire_.contacts = h.contacts;
    wire_.contact_width = h.contact_width;
    wire_.fields = h.fields;
    wire_.breaks = h.breaks;
    wire_.flags = (h.inverse_mass ? wire::kInverseMass : 0u) | (h.with_rebuild ? wire::kWithRebuild : 0u);
    wire_.rebuild_pending = h.rebuild_pending ? 1u : 0u;
    wire_.rebuild_step = h.rebuild_step;
    return wire_;
  }
  std::byte* slot(Column c, std::size_t first, std::size_t count) {
    const auto k = static_cast<std::size_t>(c);
    if (first > layout_.length[k] || count > layout_.length[k] - first)
      throw std::out_of_range("frame writer: entries [" + std::to_string(first) + ", " +
                              std::to_string(first + count) + ") of column " + std::to_string(k) +
                              " beyond its " + std::to_string(layout_.length[k]) + " entries");
    filled_[k] += count;
    return out_.data() + layout_.offset[k] + first * wire::size_of(wire::type_of(c));
  }
  template <class W, class T>
  static void store(std::byte* dst, const T* src, std::size_t n) {
    if constexpr (std::is_same_v<W, T>) {
      if (n > 0) std::memcpy(dst, src, n * sizeof(W));
    } else {
      for (std::size_t i = 0; i < n; ++i) {
        const W w = static_cast<W>(src[i]);
        std::memcpy(dst + i * sizeof(W), &w, sizeof(W));
      }
    }
  }
  template <class T>
  static void put(Column c, std::byte* dst, T value) {
    switch (wire::type_of(c)) {
      case wire::Type::i64:
        return store<std::int64_t>(dst, &value, 1);
      case wire::Type::f64:
        return store<double>(dst, &value, 1);
      case wire::Type::i32:
        return store<std::int32_t>(dst, &value, 1);
      case wire::Type::u8:
        return store<std::uint8_t>(dst, &value, 1);
    }
  }
  template <class T>
  void append(const T& v) {
    append_raw(&v, sizeof(T));
  }
  void append_raw(const void* p, std::size_t n) {
    const std::size_t at = out_.size();
    out_.resize(at + n);
    if (n > 0) std::memcpy(out_.data() + at, p, n);
  }

  std::vector<std::byte>& out_;
  FrameHeader header_;
  wire::Header wire_;
  wire::Layout layout_;
  std::array<std::size_t, kColumns> filled_{};
  std::uint64_t walls_ = 0;
  std::uint64_t fields_ = 0;
  bool attributes_ = false;
};

/// Something that can write a frame: the solver's state (solver/output/simulation_frame.hpp) or
/// a FramePiece (frame.hpp). The output client calls header(), lays out its buffer, then write().
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual FrameHeader header() const = 0;
  virtual void write(FrameWriter& w) const = 0;
};

}  // namespace basalt::io
