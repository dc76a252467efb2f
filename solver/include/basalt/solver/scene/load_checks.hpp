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

/// check_scene_with_geometry on every rank of `comm` (all hold the same geometry, so all throw alike);
/// rank 0 prints the warnings on stderr.
void run_load_checks(const Scene& scene, const io::Geometry& g, const std::string& source, MPI_Comm comm);

}  // namespace basalt::solver
