#pragma once
// A checkpoint: the full restartable state of a run at one step, as written by the I/O layer
// (schema "basalt-checkpoint" version 1, docs/formats.md). It extends the geometry schema:
// the same /particles group (sorted by id) plus velocities, the bond state and the run's clock.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "basalt/io/geometry.hpp"

namespace basalt::io {

struct WallState {
  std::string name;
  Vec3 position{0, 0, 0};  ///< a point on the plane
  Vec3 normal{0, 0, 1};
  Vec3 velocity{0, 0, 0};
  Vec3 force{0, 0, 0};  ///< force particles exert on the wall at this step
  /// Optional (/walls/<name>/motion_state): what a restart needs of a wall whose motion has no closed
  /// form (a servo wall: its position at the last neighbour-list rebuild). Empty for other walls.
  std::vector<double> motion_state;
};

struct Checkpoint {
  /// Particles (sorted by id), bonds, box, units, provenance. geometry.mass is always present.
  Geometry geometry;
  std::vector<Vec3> velocity;  ///< one per particle, same order as geometry.id
  /// Optional (empty or one per particle; /particles/inverse_mass): 1 / mass exactly as the solver
  /// held it, so that a restart reproduces the run bit for bit. geometry.mass stays the mass.
  std::vector<double> inv_mass;
  /// Optional (empty or one per particle; /particles/position_at_rebuild): each particle's position
  /// at the last neighbour-list rebuild (step rebuild_step), exactly as the solver held it. A
  /// restart replays that rebuild to get the uninterrupted run's lists bit for bit.
  std::vector<Vec3> position_at_rebuild;
  std::int64_t rebuild_step = -1;  ///< root attribute "rebuild_step"; -1 when absent
  /// Root attribute "rebuild_pending" (with position_at_rebuild): a bond broke at this step, so the
  /// next step rebuilds the lists whatever the particles moved.
  bool rebuild_pending = false;

  // Bond state, one entry per geometry.bonds entry.
  std::vector<double> bond_rest_length;
  /// 0 intact; 1 broken (broken bonds are kept so ids stay stable); 2 broke at this very step; a broken
  /// bond adds 4 x its failure mode (0 tension, 1 shear, 2 bending, 3 torsion)
  std::vector<std::uint8_t> bond_broken;
  /// Optional (/bonds/break_position, float64 (B, 3)): where each broken bond broke, one row per bond
  /// whose bond_broken is not 0, in bond order: the point between the two spheres on their line of
  /// centres at the step it broke (r1 / (r1 + r2) of the way from the first; the midpoint for equal
  /// radii), as the solver's break record holds it. A row of NaN: not known (the bond broke in a run
  /// restarted from a checkpoint without break positions). Empty: none known.
  std::vector<Vec3> bond_break_position;

  std::vector<WallState> walls;

  /// Optional per-particle fields of the scene beyond the fixed ones (e.g. broken_bonds): name and one
  /// value per particle, same order as geometry.id, as /particles/<name> float64 (N). The solver
  /// decides which of its fields go here (Particles' array list) and restores them on restart.
  std::vector<std::pair<std::string, std::vector<double>>> particle_fields;

  /// Per-contact history of the contact models that keep one (/contacts, optional): one row per
  /// contact whose history differs from a new contact's, each contact once. contact_ids[k] is the pair
  /// (the history belongs to the orientation first -> second), contact_model[k] the index of the pair
  /// model among the scene's pair models that keep history, contact_history the model's History as
  /// contact_width float64 values per contact.
  std::vector<std::array<std::int64_t, 2>> contact_ids;
  std::vector<std::int32_t> contact_model;
  std::size_t contact_width = 0;
  std::vector<double> contact_history;

  std::int64_t step = 0;
  double time = 0;
  double dt = 0;
  std::string scene_text;  ///< the scene file's text, verbatim

  std::size_t size() const { return geometry.size(); }
  /// Geometry invariants plus: one velocity per particle, one state per bond, finite values.
  void validate(const std::filesystem::path& source) const;

  // validate()'s checks in parts, for a checkpoint read in row ranges (CheckpointFile,
  // checkpoint_rows.hpp): each checks the rows this object holds, with the same messages; `first` is
  // the file row of the first one (messages count bonds, break positions and contacts from the file's
  // first row). What needs rows of other ranges (ids unique and sorted, bond and contact ends exist, no
  // pair bonded twice, one break position per broken bond) is the caller's to check.
  /// Velocities, inverse masses, positions at the last rebuild (and with `fields` the particle fields):
  /// one per particle, finite.
  void validate_particle_rows(const std::filesystem::path& source, bool fields = true) const;
  void validate_field_rows(const std::filesystem::path& source) const;
  /// Rest lengths and flags: one per bond, finite and >= 0, flags valid.
  void validate_bond_rows(const std::filesystem::path& source, std::size_t first) const;
  /// Break positions finite, or NaN in all three.
  void validate_break_rows(const std::filesystem::path& source, std::size_t first) const;
  /// Model indices >= 0, wall indices within the walls, histories finite; with `ids` (sorted), the
  /// particle ids exist.
  void validate_contact_rows(const std::filesystem::path& source, std::size_t first,
                             const std::vector<std::int64_t>* ids) const;
  /// Walls, step, time, dt.
  void validate_run(const std::filesystem::path& source) const;
  /// The message for `rows` break positions against `broken` broken bonds.
  static std::string break_rows_text(std::size_t rows, std::size_t broken);
};

/// Whether /particles/<name> is one of the schema's fixed datasets (not a particle field).
bool is_fixed_particle_dataset(const std::string& name);

/// HDF5's shuffle + deflate filters on a checkpoint's larger datasets (scene key output.compression;
/// sizes and costs measured in docs/io-ranks.md). Lossless: a restart reads the same values.
enum class Compression {
  none,   ///< contiguous, uncompressed (the default)
  fast,   ///< shuffle + deflate level 1
  small,  ///< shuffle + deflate level 6
};
/// "none", "fast" or "small"; throws std::invalid_argument naming the value otherwise.
Compression parse_compression(const std::string& name);

/// Writes atomically: to "<file>.partial", then renames; the file carries the attribute
/// /complete = 1 written last. A failure throws FormatError naming the path and leaves no file
/// under the final name.
void write_checkpoint(const Checkpoint& c, const std::filesystem::path& file,
                      Compression compression = Compression::none);
/// The same, spending `c`: each column is freed as soon as it is in the file, so writing needs little
/// more memory than the file's image (the I/O rank's checkpoints). Only c.geometry.id, the walls and
/// the run's clock and attributes are left; c.size() stays.
void write_checkpoint(Checkpoint&& c, const std::filesystem::path& file,
                      Compression compression = Compression::none);

/// Reads and validates a checkpoint; refuses (FormatError) a file without the completion mark,
/// of another schema, or of a newer schema version.
Checkpoint read_checkpoint(const std::filesystem::path& file);

/// True when `file` is a complete, readable checkpoint (never throws).
bool is_complete_checkpoint(const std::filesystem::path& file);

/// The complete checkpoint with the highest step in `dir` (ckpt_<step>.h5), or empty path.
/// `skipped`, when given, receives the newer ckpt_<step>.h5 files passed over as not complete.
std::filesystem::path latest_complete_checkpoint(const std::filesystem::path& dir,
                                                 std::vector<std::filesystem::path>* skipped = nullptr);

}  // namespace basalt::io
