#pragma once
// Checks at load of what the scene's numbers make together with the geometry's (issue 16, overflowing
// parameters): every particle's mass finite and > 0 with a finite inverse, every spring's k dt^2 / m and
// the energy of a full overlap finite, every moving wall's speed finite and its step shorter than the
// smallest radius. A failure is an InputError naming the scene key (or the geometry file) that produced
// it, before anything starts. Scene parts that match nothing in the geometry (interaction, wall or body
// force tags no particle has, a bond_tag no bond has) are warnings: they would silently do nothing.
#include <mpi.h>

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/solver/scene/scene.hpp"

namespace basalt::solver {

/// What the checks need of the particles and bonds, so that ranks each holding a slice of a geometry can
/// combine theirs (merge_summaries) and check the whole: the same numbers as from the whole geometry.
struct GeometrySummary {
  std::size_t particles = 0;
  bool has_mass = false;
  double m_min = std::numeric_limits<double>::infinity();      ///< masses as the checks compute them
  double m_min_pow = std::numeric_limits<double>::infinity();  ///< masses as the solver computes them
  double rmin = std::numeric_limits<double>::infinity(), rmax = 0;
  double xmax = 0;                        ///< largest |coordinate| of a particle centre
  std::vector<std::int64_t> tags;         ///< particle tags present, sorted, unique
  std::vector<std::int64_t> bond_tags;    ///< bond tags present, sorted, unique
  std::optional<std::string> mass_error;  ///< the first particle (file order) with an unusable mass
};

/// The summary of `g`'s particles and bonds (either may be a slice of a file's rows).
GeometrySummary summarize_geometry(const Scene& scene, const io::Geometry& g, const std::string& source);
/// Collective over `comm`: the summary of the union of every rank's slices (mass error: the lowest rank's).
GeometrySummary merge_summaries(const GeometrySummary& local, MPI_Comm comm);
/// Throws InputError for derived quantities that are not finite or not usable; returns the warnings.
std::vector<std::string> check_scene_with_summary(const Scene& scene, const GeometrySummary& s,
                                                  const std::string& source);
/// check_scene_with_summary and check_precision (machine epsilon `epsilon` of the run's `precision`) on
/// every rank (all hold the same summary, so all throw alike); rank 0 prints the warnings on stderr.
void run_load_checks(const Scene& scene, const GeometrySummary& s, const std::string& source, MPI_Comm comm,
                     double epsilon, const std::string& precision);

/// Throws InputError for derived quantities that are not finite or not usable; returns the warnings
/// (one line each). `source` names where the particles came from (geometry file or checkpoint).
std::vector<std::string> check_scene_with_geometry(const Scene& scene, const io::Geometry& g,
                                                   const std::string& source);

/// Strain resolution of positions in a precision of machine epsilon `epsilon`: eps |x|max / (2 rmin),
/// the relative rounding of the distance of two of the smallest particles at the geometry's largest
/// |coordinate| (rounding grows with the offset from the origin, not with the geometry's size).
double strain_resolution(const GeometrySummary& s, double epsilon);

/// Warning limit of strain_resolution (on the wave benchmark the kinetic energy's L2 error was 40-1200
/// times the resolution: docs/stability.md) and the limit above which a run is refused.
inline constexpr double kResolutionWarn = 1e-5, kResolutionRefuse = 1e-4;

/// Throws InputError when strain_resolution(s, epsilon) exceeds kResolutionRefuse; returns a warning
/// above kResolutionWarn, else an empty string. `precision` names the type ("double", "float").
std::string check_precision(const GeometrySummary& s, double epsilon, const std::string& precision,
                            const std::string& source);

}  // namespace basalt::solver
