#pragma once
// Helpers shared by the I/O tests: small geometries with every feature set, file bytes,
// and a check that an exception's message names what it should.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <initializer_list>
#include <string>

#include "basalt/io/geometry.hpp"

namespace basalt::io::test {

/// Six particles with unsorted, non-contiguous ids, masses, four bonds (one stored b < a),
/// units, box, periodic flags, provenance and statistics.
Geometry sample_geometry();

std::string read_bytes(const std::filesystem::path& file);
void write_bytes(const std::filesystem::path& file, const std::string& bytes);

/// Runs `f`, expects a FormatError whose message contains every fragment
/// (BASALT_TEST_SHOW_ERRORS=1 prints each message, to review their wording).
void expect_format_error(const std::function<void()>& f, std::initializer_list<std::string> fragments);

/// Particle-by-particle equality (ids, exact positions, radii, tags, masses) and bonds.
void expect_same_particles_and_bonds(const Geometry& a, const Geometry& b);

}  // namespace basalt::io::test
