#pragma once
// Checks at load of what the scene's numbers make together with the geometry's (issue 16, overflowing
// parameters): every particle's mass finite and > 0 with a finite inverse, every spring's k dt^2 / m and
// the energy of a full overlap finite, every moving wall's speed finite and its step shorter than the
// smallest radius. A failure is an InputError naming the scene key (or the geometry file) that produced
// it, before anything starts. Scene parts that match nothing in the geometry (interaction, wall or body
// force tags no particle has, a bond_tag no bond has) are warnings: they would silently do nothing.
#include <mpi.h>

#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::solver {

/// Throws InputError for derived quantities that are not finite or not usable; returns the warnings
/// (one line each). `source` names where the particles came from (geometry file or checkpoint).
std::vector<std::string> check_scene_with_geometry(const Scene& scene, const io::Geometry& g,
                                                   const std::string& source);

/// Strain resolution of positions in a precision of machine epsilon `epsilon`: eps |x|max / (2 rmin),
/// the relative rounding of the distance of two of the smallest particles at the geometry's largest
/// |coordinate| (rounding grows with the offset from the origin, not with the geometry's size).
double strain_resolution(const io::Geometry& g, double epsilon);

/// Warning limit of strain_resolution (on the wave benchmark the kinetic energy's L2 error was 40-1200
/// times the resolution: docs/stability.md) and the limit above which a run is refused.
inline constexpr double kResolutionWarn = 1e-5, kResolutionRefuse = 1e-4;

/// Throws InputError when strain_resolution(g, epsilon) exceeds kResolutionRefuse; returns a warning
/// above kResolutionWarn, else an empty string. `precision` names the type ("double", "float").
std::string check_precision(const io::Geometry& g, double epsilon, const std::string& precision,
                            const std::string& source);

/// check_scene_with_geometry on every rank of `comm` (all hold the same geometry, so all throw alike);
/// rank 0 prints the warnings on stderr.
void run_load_checks(const Scene& scene, const io::Geometry& g, const std::string& source, MPI_Comm comm,
                     double epsilon, const std::string& precision);

}  // namespace basalt::solver
