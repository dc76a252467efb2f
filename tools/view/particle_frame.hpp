#pragma once
// What basalt-view draws or converts: one frame of particles read from a checkpoint (.h5),
// a geometry (.h5/.geo) or a VTK file (.vtp/.pvtp), as a vtkPolyData with named point arrays.
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "basalt/io/checkpoint.hpp"
#include "basalt/io/vtk_frames.hpp"

namespace basalt::view {

/// Particles read from a Basalt file, owning their arrays.
struct ParticleSet {
  io::Geometry geometry;
  std::vector<io::Vec3> velocity;      ///< empty for a geometry
  std::vector<io::Vec3> displacement;  ///< filled when a reference was given
  /// A checkpoint's optional particle fields (angular_velocity_x ..., the scene's), one value per particle.
  std::vector<std::pair<std::string, std::vector<double>>> fields;
  /// Bond damage (broken / initial bonds of each particle) of a checkpoint whose scene has breakable bonds
  /// (its bonds_initial and bonds_broken fields); empty otherwise.
  std::vector<double> damage;
  /// A checkpoint's broken bonds, one point each where it broke (crack_points()); empty otherwise.
  std::vector<io::Vec3> cracks;
  std::size_t cracks_estimated = 0;  ///< of them, placed from the ends' current positions (no record)
  io::FrameInfo info;
  std::string kind;  ///< "checkpoint" or "geometry"

  io::ParticleArrays arrays() const;
};

/// Reads a checkpoint or geometry (.h5, .hdf5, .geo). With `reference` (a geometry or checkpoint
/// holding the initial positions), fills `displacement`. Throws io::FormatError naming the file.
ParticleSet read_particles(const std::filesystem::path& file,
                           const std::optional<std::filesystem::path>& reference);

/// Where each broken bond of a checkpoint broke, one point per bond whose /bonds/broken is not 0, in bond
/// order: its recorded break position (/bonds/break_position: the point between the two spheres on their
/// line of centres, r1 / (r1 + r2) of the way from the first, at the step it broke), or, for a checkpoint
/// without it (or a row of NaN), the same point from the two ends' positions in this checkpoint, counted
/// in `estimated`.
std::vector<io::Vec3> crack_points(const io::Checkpoint& c, std::size_t& estimated);

struct Frame {
  vtkSmartPointer<vtkPolyData> polydata;
  io::FrameInfo info;
  std::string kind;              ///< "checkpoint", "geometry" or "VTK frame"
  std::vector<io::Vec3> cracks;  ///< broken bonds (checkpoints)
  std::size_t cracks_estimated = 0;
};

/// Any file basalt-view reads, as polydata (.vtp/.pvtp through VTK's readers).
Frame read_frame(const std::filesystem::path& file, const std::optional<std::filesystem::path>& reference);

}  // namespace basalt::view
