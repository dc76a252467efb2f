// Rotational bonds across ranks: a small bonded specimen (rot_bond with BrittleBeam strengths, rot_friction
// contacts) crushed between two platens gives the same platen force (1e-8 relative), the same bond count and
// the same broken bonds per failure mode at every saved step on 1, 2 and 4 ranks and any rank grid, through
// the first 100 breaks: a bond across two ranks breaks once, on both at the same step.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <mpi.h>

#include <array>
#include <cmath>

#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;

namespace {

constexpr int kSteps = 1200;

std::string scene_text(double top) {
  return fmt::format(R"(
[particles]
rotation = true
[run]
dt = 5.0e-5
steps = 0
skin = 0.05
[[interactions]]
type = "rot_bond"
youngs_modulus = 1.0e5
poissons_ratio = 0.25
cohesion = 100.0
tan_friction_angle = 1.0
rest_length = "sum_of_radii"
[[interactions]]
type = "rot_friction"
K = 1.0e5
Ks = 1.0e5
mu = 0.6
mu_dynamic = 0.4
scaling = true
[[walls]]
name = "bottom"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
K = 1.0e5
stiffness = "esys_pi_r"
motion = {{ type = "constant_velocity", velocity = [0.0, 0.0, 1.5] }}
[[walls]]
name = "top"
point = [0.0, 0.0, {}]
normal = [0.0, 0.0, -1.0]
K = 1.0e5
stiffness = "esys_pi_r"
motion = {{ type = "constant_velocity", velocity = [0.0, 0.0, -1.5] }}
[output]
[[output.fields]]
type = "wall_force"
wall = "top"
every = 10
[[output.fields]]
type = "bond_count"
every = 10
[[output.fields]]
type = "broken_bonds"
every = 10
)",
                     top);
}

std::vector<std::vector<double>> series(const Scene& scene, const basalt::io::Geometry& g, MPI_Comm comm,
                                        std::array<int, 3> dims) {
  const auto sink = basalt::test::run_fields(scene, g, comm, kSteps, dims);
  std::vector<std::vector<double>> cols;
  for (std::size_t c = 0; c < sink.columns.size(); ++c) cols.push_back(sink.column(c));
  return cols;
}

}  // namespace

TEST(RotBondParallel, CrushedSpecimenMatchesSerialRunThroughBreaks) {
  const auto full = basalt::test::cube1();
  const auto g = basalt::test::sub_cube(full, 0.0, 9.0);
  double top = 0;
  for (std::size_t i = 0; i < g.size(); ++i) top = std::max(top, g.position[i][2] + g.radius[i]);
  const auto scene = basalt::test::scene_from(scene_text(top));
  const auto columns = field_columns(scene);
  const std::size_t fz = 2, count = 3, modes = 4;  // wall_force_top_z, bond_count, broken_bonds_*
  ASSERT_EQ(columns[fz], "wall_force_top_z");
  ASSERT_EQ(columns[count], "bond_count");
  const int n = basalt::test::size();
  const std::size_t rows = kSteps / 10;
  std::vector<double> ref(columns.size() * rows);
  if (basalt::test::rank() == 0) {
    const auto s = series(scene, g, MPI_COMM_SELF, {1, 1, 1});
    for (std::size_t c = 0; c < columns.size(); ++c)
      std::copy(s[c].begin(), s[c].end(), ref.begin() + c * rows);
  }
  MPI_Bcast(ref.data(), int(ref.size()), MPI_DOUBLE, 0, basalt::test::world());
  const auto col = [&](std::size_t c, std::size_t k) { return ref[c * rows + k]; };
  // The run must break bonds, in more than one mode, and load the platen.
  double broke = 0, fmax = 0;
  for (std::size_t m = 0; m < 4; ++m) broke += col(modes + m, rows - 1);
  for (std::size_t k = 0; k < rows; ++k) fmax = std::max(fmax, std::abs(col(fz, k)));
  ASSERT_GT(broke, 10) << "no bonds broke: the test would prove nothing";
  EXPECT_EQ(col(count, 0) - col(count, rows - 1), broke) << "broken bonds counted once";
  ASSERT_GT(fmax, 0);

  std::vector<std::array<int, 3>> grids{{0, 0, 0}};
  if (n == 2) grids.insert(grids.end(), {{1, 1, 2}, {2, 1, 1}});
  if (n == 4) grids.insert(grids.end(), {{1, 1, 4}, {2, 2, 1}});
  for (const auto& dims : grids) {
    const auto s = series(scene, g, basalt::test::world(), dims);
    if (basalt::test::rank() != 0) continue;
    // Breaking is a threshold: once a bond at the margin breaks on one grid and not the other (force sums
    // in another order differ by rounding), the runs part ways. Until then they agree: the same broken
    // bonds per mode at every row, that stretch must hold the first 100 breaks.
    std::size_t same = 0;
    bool counts_agree = true;
    while (same < rows && counts_agree) {
      counts_agree = s[count][same] == col(count, same);
      for (std::size_t m = 0; m < 4; ++m)
        counts_agree = counts_agree && s[modes + m][same] == col(modes + m, same);
      if (counts_agree) ++same;
    }
    // The platen force to 5e-8 through the first 100 breaks (measured 2.5e-9 to 1.9e-8 since orientations are
    // renormalised every step and q^-1 is the conjugate, as in ESyS; 1e-9 to 6e-9 before: this specimen is
    // crushed in 0.06 ms and each break passes on the other grid's rounding).
    std::size_t first100 = 0;
    while (first100 < same && col(count, 0) - col(count, first100) < 100) ++first100;
    double worst = 0;
    for (std::size_t k = 0; k <= first100 && k < same; ++k)
      worst = std::max(worst, std::abs(s[fz][k] - col(fz, k)) / fmax);
    const double broken_while_same = same > 0 ? col(count, 0) - col(count, same - 1) : 0;
    EXPECT_GE(broken_while_same, 100) << "dims " << dims[0] << "," << dims[1] << "," << dims[2]
                                      << ": broken bonds differ from the serial run at row " << same;
    EXPECT_LT(worst, 5e-8) << "dims " << dims[0] << "," << dims[1] << "," << dims[2];
    std::printf(
        "np %d dims %d,%d,%d: identical broken bonds for %zu of %zu rows (%g breaks), platen force max "
        "rel. difference %.3g there; serial total %g broken (t %g s %g b %g t %g)\n",
        n, dims[0], dims[1], dims[2], same, rows, broken_while_same, worst, broke, col(modes, rows - 1),
        col(modes + 1, rows - 1), col(modes + 2, rows - 1), col(modes + 3, rows - 1));
  }
}
