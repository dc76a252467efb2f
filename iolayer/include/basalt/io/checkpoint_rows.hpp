#pragma once
// Reading a basalt-checkpoint HDF5 file in parts, as geometry_rows.hpp reads geometry files: its header
// (row counts, which optional datasets it has, walls, clock, attributes), then any range of particle rows,
// of bond rows, of /bonds/break_position rows and of contact rows, each an HDF5 hyperslab. basalt-run's
// restart has each compute rank read one slice of each and route the rows to the ranks owning them
// (solver/src/checkpoint_loader.cpp), so that no process holds the whole checkpoint. read_checkpoint
// (checkpoint.hpp) still reads whole files for tools and tests.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "basalt/io/checkpoint.hpp"

namespace basalt::io {

/// A checkpoint file's description without its rows.
struct CheckpointHeader {
  std::size_t particles = 0;
  std::size_t bonds = 0;
  std::size_t break_positions = 0;  ///< rows of /bonds/break_position (0 when absent)
  bool has_break_position = false;
  std::size_t contacts = 0;
  bool has_inverse_mass = false;
  bool has_position_at_rebuild = false;
  std::vector<std::string> particle_fields;  ///< /particles/<name> beyond the fixed datasets, in file order
  /// Everything that is not rows: the geometry's box, units, periodic flags and attributes (no
  /// particles or bonds), walls, step, time, dt, scene text, rebuild_step, rebuild_pending, contact_width.
  Checkpoint run;
};

/// The header of a checkpoint held whole (basalt-run --whole-checkpoint).
CheckpointHeader header_of(const Checkpoint& c);

/// One open checkpoint file. Errors are FormatErrors naming the file and the dataset, with
/// read_checkpoint's messages.
class CheckpointFile {
 public:
  /// Opens the file; checks its schema, completion mark, every dataset's type and shape, the walls and
  /// the clock (reads no rows).
  explicit CheckpointFile(const std::filesystem::path& file);
  ~CheckpointFile();
  CheckpointFile(const CheckpointFile&) = delete;
  CheckpointFile& operator=(const CheckpointFile&) = delete;

  const std::filesystem::path& path() const;
  const CheckpointHeader& header() const { return header_; }

  /// Particle rows [begin, end) into `out`: geometry id, position, radius, tag, mass; velocity, inverse
  /// mass and position at the last rebuild (when the file has them), every particle field; replacing what
  /// those held. Checked as read_checkpoint checks them; ids strictly ascending within these rows (across
  /// ranges: the caller's check).
  void read_particles(std::size_t begin, std::size_t end, Checkpoint& out) const;
  /// Bond rows [begin, end) into out.geometry.bonds, out.bond_rest_length and out.bond_broken. Each pair
  /// is checked a != b and a < b; that its ids exist and that no pair is bonded twice is the caller's check.
  void read_bonds(std::size_t begin, std::size_t end, Checkpoint& out) const;
  /// Rows [begin, end) of /bonds/break_position (one per broken bond, in bond order) into
  /// out.bond_break_position. That there is one per broken bond is the caller's check.
  void read_break_positions(std::size_t begin, std::size_t end, Checkpoint& out) const;
  /// Contact rows [begin, end) into out.contact_ids, contact_model, contact_history (out.contact_width
  /// set); wall indices checked against the walls. That particle ids exist is the caller's check.
  void read_contacts(std::size_t begin, std::size_t end, Checkpoint& out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  CheckpointHeader header_;
};

}  // namespace basalt::io
