#pragma once
// basalt-run's geometry input: an HDF5 geometry is read in slices by every compute rank
// (io::GeometryFile, solver GeometryLoader); an ESyS-Particle .geo (text, not sliceable) is first
// converted to HDF5 once, by compute rank 0, into the output folder.
#include <filesystem>
#include <memory>

#include "basalt/io/geometry_rows.hpp"
#include "basalt/io/io_ranks.hpp"
#include "basalt/solver/parallel/communicator.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::run {

/// `file` itself for .h5/.hdf5; for .geo, collective over `comm`: compute rank 0
/// reads it and writes `<output_dir>/<stem>.from-geo.h5`, and every rank gets that path. A bad .geo is an
/// InputError naming it on every rank.
std::filesystem::path geometry_as_h5(const std::filesystem::path& file,
                                     const std::filesystem::path& output_dir, const solver::Comm& comm,
                                     bool quiet);

/// The start-up from the scene's geometry (basalt-run without --restart, Python's Simulation), collective
/// over `comm`: the file as HDF5 (geometry_as_h5) opened on every rank for sliced reading (a failure on
/// any rank is an InputError alike on all). Compute rank 0 warns on stderr when the units the geometry
/// declares differ from the scene's. `info` takes the geometry's box, periodic flags and units.
std::unique_ptr<io::GeometryFile> open_geometry(const solver::Scene& scene,
                                                const std::filesystem::path& output_dir,
                                                const solver::Comm& comm, bool quiet, io::RunInfo& info);

}  // namespace basalt::run
