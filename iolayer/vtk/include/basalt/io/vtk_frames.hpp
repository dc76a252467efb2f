#pragma once
// VTK XML frames for ParaView, written through VTK's own writers (no plugin needed to read them):
//   one .vtp per writer piece   <frame_dir>/frame_<step>/piece_<i>.vtp   (binary appended data)
//   one .pvtp per frame         <frame_dir>/frame_<step>.pvtp           (lists the pieces)
//   one .pvd per series         lists (time, file) of every frame, rewritten atomically on add()
// A serial writer calls write_vtp(); the I/O ranks each call write_piece() for their own piece and one
// of them calls write_pvtp() and PvdSeries::add() once all pieces of a step are written.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "basalt/io/checkpoint.hpp"

namespace basalt::io {

/// Per-particle arrays of one piece (non-owning views). position, id, radius and tag are required;
/// velocity, mass and displacement are written when non-empty. All have the same length.
struct ParticleArrays {
  std::span<const std::int64_t> id;
  std::span<const Vec3> position;
  std::span<const double> radius;
  std::span<const std::int32_t> tag;
  std::span<const Vec3> velocity;      ///< optional; also gives the "speed" array
  std::span<const double> mass;        ///< optional
  std::span<const Vec3> displacement;  ///< optional: position minus the reference (initial) position
  /// Optional particle fields (Checkpoint::particle_fields), one Float64 array each.
  std::vector<std::pair<std::string, std::span<const double>>> fields;

  std::size_t size() const { return id.size(); }
  /// Throws std::invalid_argument when the lengths disagree.
  void check() const;
};

/// The run's clock and units, stored as field data in each .vtp (step, time, TimeValue, units).
struct FrameInfo {
  std::int64_t step = 0;
  double time = 0;
  bool has_clock = false;  ///< false for a geometry (no step/time)
  Units units;
};

/// Views of a checkpoint's arrays; `displacement` (may be empty) is passed through.
ParticleArrays arrays_of(const Checkpoint& c, std::span<const Vec3> displacement = {});
ParticleArrays arrays_of(const Geometry& g, std::span<const Vec3> displacement = {});
FrameInfo info_of(const Checkpoint& c);

/// Displacement of each particle of `current` from the particle with the same id in `reference`.
/// Throws FormatError (naming `reference_file`) when an id of `current` is missing from it.
std::vector<Vec3> displacement_from(const Geometry& current, const Geometry& reference,
                                    const std::filesystem::path& reference_file);

/// One array of the point data as the .pvtp must announce it.
struct ArrayLayout {
  std::string name;
  std::string type;  ///< VTK XML type name: Int64, Int32, Float64
  int components = 1;
  friend bool operator==(const ArrayLayout&, const ArrayLayout&) = default;
};
/// The point-data arrays a piece made from `a` holds, in order (same on every piece of a frame).
std::vector<ArrayLayout> layout_of(const ParticleArrays& a);
/// The same, from which optional arrays are present.
std::vector<ArrayLayout> frame_layout(bool mass, bool velocity, bool displacement);

/// Writes one .vtp (atomically: temporary name, then rename). Throws FormatError naming the file.
/// With `layout`, the file holds exactly those arrays (see write_piece).
void write_vtp(const ParticleArrays& a, const FrameInfo& info, const std::filesystem::path& file,
               const std::vector<ArrayLayout>* layout = nullptr);
void write_vtp(const Checkpoint& c, const std::filesystem::path& file,
               std::span<const Vec3> displacement = {});

std::filesystem::path piece_path(const std::filesystem::path& frame_dir, std::int64_t step, int piece);
std::filesystem::path pvtp_path(const std::filesystem::path& frame_dir, std::int64_t step);

/// Writes piece `piece` (0 <= piece < n_pieces) of frame `step`; returns its path. Every piece of a
/// frame must hold the same arrays: `layout` (the one given to write_pvtp) says which. A piece with no
/// particles gets empty arrays of that layout; a non-empty piece whose arrays differ from it is refused
/// (std::invalid_argument), since ParaView would refuse the whole frame.
std::filesystem::path write_piece(const std::filesystem::path& frame_dir, std::int64_t step, int piece,
                                  int n_pieces, const ParticleArrays& a, const FrameInfo& info,
                                  const std::vector<ArrayLayout>& layout);
/// Writes the frame's .pvtp listing pieces 0..n_pieces-1 (relative paths) with the given arrays;
/// returns its path. Pieces need not exist yet: ParaView reads them when it opens the .pvtp.
std::filesystem::path write_pvtp(const std::filesystem::path& frame_dir, std::int64_t step, int n_pieces,
                                 const std::vector<ArrayLayout>& layout);

/// A ParaView collection (.pvd) of frames in time order.
class PvdSeries {
 public:
  /// Starts an empty series at `pvd`; with `resume`, keeps the entries of an existing file there.
  explicit PvdSeries(std::filesystem::path pvd, bool resume = false);
  /// Appends (time, file) and rewrites the .pvd atomically. `file` may be absolute or relative to
  /// the .pvd's folder; it is stored relative to that folder.
  void add(double time, const std::filesystem::path& file);
  /// Drops entries with time > t (a restart from an earlier checkpoint) and rewrites the file.
  void truncate_after(double t);
  /// Drops entries with time >= t (before a restart writes the frame at t again); rewrites the file.
  void truncate_before_or_at(double t);

  struct Entry {
    double time;
    std::string file;  ///< relative to the .pvd's folder
  };
  const std::vector<Entry>& entries() const { return entries_; }
  const std::filesystem::path& path() const { return pvd_; }

 private:
  void rewrite() const;
  std::filesystem::path pvd_;
  std::vector<Entry> entries_;
};

}  // namespace basalt::io
