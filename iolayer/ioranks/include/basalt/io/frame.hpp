#pragma once
// One compute rank's share of a run's state at one output step ("frame piece") as the I/O side
// holds it. Compute ranks write their frame straight into the send buffer (frame_writer.hpp);
// the I/O side reads it into a FramePiece and assembles the pieces of all ranks into a
// Checkpoint (sorted by id) or writes them as VTK.
#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "basalt/io/checkpoint.hpp"
#include "basalt/io/frame_writer.hpp"

namespace basalt::io {

struct FramePiece {
  std::uint32_t kinds = 0;  ///< FrameKind bits
  std::int64_t step = 0;
  double time = 0;
  std::int32_t source_rank = 0;  ///< compute rank that packed it

  // Owned particles of the source rank (any order).
  std::vector<std::int64_t> id;
  std::vector<Vec3> position;
  std::vector<Vec3> velocity;
  std::vector<double> radius;
  std::vector<double> mass;  ///< with inverse masses on the wire: 1 / inv_mass, derived on arrival
  std::vector<std::int32_t> tag;
  /// Optional (empty or one per particle): 1 / mass exactly as the solver holds it, so that a
  /// restart gets the same bits (1 / (1 / m) is not always m in floating point).
  std::vector<double> inv_mass;
  /// Optional (empty or one per particle): each particle's position at the last neighbour-list
  /// rebuild, exactly as the solver held it; with rebuild_step it lets a restart replay that
  /// rebuild (bit-for-bit continuation, docs/ARCHITECTURE.md).
  std::vector<Vec3> position_at_rebuild;
  std::int64_t rebuild_step = -1;    ///< step of the last neighbour-list rebuild (-1: unknown)
  std::uint8_t rebuild_pending = 0;  ///< 1: the next step rebuilds whatever moved (a bond broke)

  // Bonds this rank is responsible for (each bond in exactly one piece), with their state.
  std::vector<Bond> bonds;
  std::vector<double> bond_rest_length;
  std::vector<std::uint8_t> bond_broken;
  /// Empty, or where each broken bond (bond_broken != 0) broke, in bond order (NaN: not known).
  std::vector<Vec3> bond_break_position;

  // Contact history this rank is responsible for (each contact in exactly one piece).
  std::vector<std::array<std::int64_t, 2>> contact_ids;
  std::vector<std::int32_t> contact_model;
  std::size_t contact_width = 0;
  std::vector<double> contact_history;

  /// Optional particle fields (Checkpoint::particle_fields): name, one value per particle (id order).
  std::vector<std::pair<std::string, std::vector<double>>> fields;

  // Global, identical on every rank; only the piece of compute rank 0 needs to carry them.
  std::vector<WallState> walls;
  /// The frame's own checkpoint attributes (FrameWriter::attributes): they override the run's.
  std::map<std::string, std::string> attributes;

  std::size_t size() const { return id.size(); }
  void clear();  ///< empties the arrays, keeping their capacity
};

/// A FramePiece as a FrameSource (I/O ranks forwarding pieces, tests). With inverse masses the
/// wire carries those and the reader derives the masses (1 / inv_mass, as the solver would).
/// header() throws std::invalid_argument when the arrays differ in length.
class PieceSource final : public FrameSource {
 public:
  explicit PieceSource(const FramePiece& piece) : p_(piece) {}
  FrameHeader header() const override;
  void write(FrameWriter& w) const override;

 private:
  const FramePiece& p_;
};

/// The wire format of frame_writer.hpp: writes `source` into `out`; returns its size in bytes.
std::size_t serialize(const FrameSource& source, std::vector<std::byte>& out);
/// Same for a piece. Round-trips exactly (masses: see PieceSource).
void serialize(const FramePiece& piece, std::vector<std::byte>& out);
/// Throws std::runtime_error on a malformed buffer (bad magic, sizes that overrun the buffer).
FramePiece deserialize(std::span<const std::byte> bytes);

/// What a checkpoint needs besides the per-rank pieces: fixed for the whole run, so it travels once
/// (at start, to every I/O rank), not in every frame.
struct RunInfo {
  double dt = 0;  ///< the time step (checkpoints store it)
  Vec3 box_min{0, 0, 0};
  Vec3 box_max{0, 0, 0};
  std::array<bool, 3> periodic{false, false, false};
  Units units;
  std::map<std::string, std::string> attributes;  ///< provenance (code version, command line ...)
  std::string scene_text;
};

/// Joins the pieces of one step into a checkpoint: particles sorted by id, bonds sorted by
/// (a, b), walls from whichever piece carries them. Throws std::runtime_error if pieces
/// disagree on the step or a particle id appears twice.
Checkpoint assemble(std::vector<FramePiece>& pieces, const RunInfo& run);
/// The same, spending the pieces: each piece's column is freed once copied into the checkpoint, so the
/// pieces and the checkpoint never hold much more than one copy of the data between them (what the
/// I/O rank needs for a checkpoint of millions of particles). The pieces are left empty but for their
/// header fields, walls and attributes.
Checkpoint assemble(std::vector<FramePiece>&& pieces, const RunInfo& run);

/// RunInfo as a flat buffer (sent once from compute rank 0 to every I/O rank at start).
void serialize(const RunInfo& info, std::vector<std::byte>& out);
RunInfo deserialize_run_info(std::span<const std::byte> bytes);

}  // namespace basalt::io
