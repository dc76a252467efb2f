#pragma once
// basalt-run's geometry input: an HDF5 geometry is read in slices by every compute rank
// (io::GeometryFile, solver GeometryLoader); an ESyS-Particle .geo (text, not sliceable) is first
// converted to HDF5 once, by compute rank 0, into the output folder.
#include <filesystem>

#include "basalt/solver/parallel/communicator.hpp"

namespace basalt::run {

/// `file` itself for .h5/.hdf5; for .geo, collective over `comm`: compute rank 0
/// reads it and writes `<output_dir>/<stem>.from-geo.h5`, and every rank gets that path. A bad .geo is an
/// InputError naming it on every rank.
std::filesystem::path geometry_as_h5(const std::filesystem::path& file,
                                     const std::filesystem::path& output_dir, const solver::Comm& comm,
                                     bool quiet);

}  // namespace basalt::run
