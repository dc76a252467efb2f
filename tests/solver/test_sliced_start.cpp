// The sliced start-up (each rank reads a slice of the geometry file's rows and the ranks route them to
// their owners, solver/src/geometry_loader.cpp) gives exactly the state of the whole-file start-up: the
// same owned particles in the same order, the same bonds with the same rest lengths and groups, the same
// damage counters, and the same run. And no rank reads more than its share of the file's rows.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "basalt/io/geometry_rows.hpp"
#include "basalt/solver/parallel/geometry_loader.hpp"
#include "basalt/solver/parallel/id_slices.hpp"
#include "basalt/solver/scene/load_checks.hpp"
#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt::solver;
namespace io = basalt::io;

namespace {

template <class A>
void expect_same_array(const A& a, const A& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  std::size_t diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff += !(a[i] == b[i]);
  EXPECT_EQ(diff, 0u) << what;
}

void expect_same_state(const Simulation<double>& a, const Simulation<double>& b) {
  const auto &p = a.particles(), &q = b.particles();
  ASSERT_EQ(p.n_owned, q.n_owned);
  expect_same_array(p.id, q.id, "id");
  expect_same_array(p.x, q.x, "x");
  expect_same_array(p.y, q.y, "y");
  expect_same_array(p.z, q.z, "z");
  expect_same_array(p.vx, q.vx, "vx");
  expect_same_array(p.vz, q.vz, "vz");
  expect_same_array(p.radius, q.radius, "radius");
  expect_same_array(p.inv_mass, q.inv_mass, "inv_mass");
  expect_same_array(p.bonds_initial, q.bonds_initial, "bonds_initial");
  expect_same_array(p.bonds_broken, q.bonds_broken, "bonds_broken");
  expect_same_array(a.bonds().a, b.bonds().a, "bond a");
  expect_same_array(a.bonds().b, b.bonds().b, "bond b");
  expect_same_array(a.bonds().r0, b.bonds().r0, "bond r0");
  expect_same_array(a.bonds().group, b.bonds().group, "bond group");
  EXPECT_EQ(a.unassigned_bonds(), b.unassigned_bonds());
  EXPECT_EQ(a.ghost_width(), b.ghost_width());
  EXPECT_EQ(a.dt(), b.dt());
}

/// Runs the scene from the whole geometry and from the file read in slices; compares state and energies.
void compare_starts(const Scene& scene, const std::filesystem::path& h5) {
  Simulation<double> whole(scene, io::read_geometry(h5), MPI_COMM_WORLD);
  io::GeometryFile file(h5);
  Simulation<double> sliced(scene, file, MPI_COMM_WORLD);
  expect_same_state(whole, sliced);
  basalt::test::MemorySink sa(scene), sb(scene);
  whole.run(60, &sa);
  sliced.run(60, &sb);
  expect_same_state(whole, sliced);
  EXPECT_EQ(sa.rows, sb.rows);
  EXPECT_EQ(whole.broken_bonds().size(), sliced.broken_bonds().size());

  // Rows read: this rank's slice only; particles held: owned ones and the far ends of its bonds, which
  // are within the ghost width, so no more than the ghosts the halo holds.
  const int p = basalt::test::size();
  const auto& st = sliced.load_stats();
  const auto n = file.header().particles, m = file.header().bonds;
  EXPECT_LE(st.particle_rows, (n + std::size_t(p) - 1) / std::size_t(p));
  EXPECT_LE(st.bond_rows, (m + std::size_t(p) - 1) / std::size_t(p));
  EXPECT_LE(st.ghost_ends, sliced.particles().id.size() - sliced.particles().n_owned);
  EXPECT_EQ(sliced.comm().sum(static_cast<long long>(st.owned)), static_cast<long long>(n));
  EXPECT_EQ(sliced.comm().sum(static_cast<long long>(st.particle_rows)), static_cast<long long>(n));
  EXPECT_EQ(sliced.comm().sum(static_cast<long long>(st.bond_rows)), static_cast<long long>(m));
  if (p > 1) {
    EXPECT_LT(st.owned + st.ghost_ends, n);
  }
}

}  // namespace

TEST(SlicedStart, WaveCubeSameAsWholeFile) {
  const auto dir = basalt::test::scratch_dir("sliced-start");
  const auto h5 = dir / "cube1.h5";
  if (basalt::test::rank() == 0) io::write_geometry(basalt::test::cube1(), h5);
  MPI_Barrier(MPI_COMM_WORLD);
  auto scene = parse_scene(basalt::test::source_dir() / "scenes" / "wave.toml");
  compare_starts(scene, h5);
}

TEST(SlicedStart, TagsMassesGroupsAndBreakingSameAsWholeFile) {
  // Masses in the file, three particle tags, two bond tags: two bond groups chosen by particle tags and
  // by bond tag, a breakable group (damage counters), bonds no group takes (counted once).
  const auto dir = basalt::test::scratch_dir("sliced-start-tags");
  const auto h5 = dir / "tagged.h5";
  if (basalt::test::rank() == 0) {
    auto g = basalt::test::cube1();
    g.mass.resize(g.size());
    for (std::size_t i = 0; i < g.size(); ++i) {
      g.tag[i] = static_cast<std::int32_t>(g.id[i] % 3);
      g.mass[i] = 4.2 * g.radius[i] * g.radius[i] * g.radius[i] * (1 + 0.1 * basalt::test::hash_unit(i));
    }
    for (std::size_t k = 0; k < g.bonds.size(); ++k) g.bonds[k].tag = static_cast<std::int32_t>(k % 2);
    io::write_geometry(g, h5);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  const auto scene = basalt::test::scene_from(R"(
[run]
dt = 1.0e-3
steps = 60
skin = 0.1
[[interactions]]
name = "strong"
type = "linear_bond"
K = 1000.0
tags = [0, 1]
[[interactions]]
name = "weak"
type = "linear_bond"
K = 500.0
bond_tag = 1
break_strain = 0.001
[[interactions]]
name = "contacts"
type = "linear_elastic"
K = 1000.0
[[walls]]
name = "base"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
K = 1000.0
motion = { type = "half_sine", amplitude = 0.5, period = 0.2 }
[[output.fields]]
type = "kinetic_energy"
every = 1
)");
  compare_starts(scene, h5);
}

TEST(SlicedStart, LoadChecksSeeTheBondTagsOfTheSlices) {
  // cube1.geo as ESyS-Particle's GenGeo writes it: every bond tagged 0 (its default). A bond group with
  // bond_tag = 0 takes all of them, so the load check must not report that no bond has that tag (it
  // did: the slices it summarised held particles only); a tag no bond has is still reported.
  const auto dir = basalt::test::scratch_dir("sliced-start-bond-tags");
  const auto h5 = dir / "cube1.h5";
  const auto whole = basalt::test::cube1();
  ASSERT_FALSE(whole.bonds.empty());
  for (const auto& b : whole.bonds) ASSERT_EQ(b.tag, 0);
  if (basalt::test::rank() == 0) io::write_geometry(whole, h5);
  MPI_Barrier(MPI_COMM_WORLD);
  const auto scene_with = [](int tag) {
    return basalt::test::scene_from(fmt::format(R"(
[run]
dt = 1.0e-3
steps = 1
skin = 0.1
[[interactions]]
name = "bonds"
type = "linear_bond"
K = 1000.0
bond_tag = {}
)",
                                                tag));
  };
  const auto scene = scene_with(0);
  io::GeometryFile file(h5);
  const Comm comm(MPI_COMM_WORLD);
  GeometryLoader loader(file, comm);
  const auto sliced = merge_summaries(summarize_geometry(scene, loader.slice(), "cube1.h5"), MPI_COMM_WORLD);
  const auto full = summarize_geometry(scene, whole, "cube1.h5");
  EXPECT_EQ(sliced.bond_tags, full.bond_tags);
  EXPECT_EQ(sliced.bond_tags, std::vector<std::int64_t>{0});
  EXPECT_EQ(sliced.tags, full.tags);
  EXPECT_TRUE(check_scene_with_summary(scene, sliced, "cube1.h5").empty());
  const auto absent = check_scene_with_summary(scene_with(3), sliced, "cube1.h5");
  ASSERT_EQ(absent.size(), 1u);
  EXPECT_NE(absent[0].find("bond_tag = 3: no bond of cube1.h5 has that tag"), std::string::npos) << absent[0];
  // The run from the slices takes every bond with bond_tag = 0.
  Simulation<double> sim(scene, file, MPI_COMM_WORLD);
  EXPECT_EQ(sim.unassigned_bonds(), 0u);
  EXPECT_EQ(sim.bond_count(), static_cast<std::int64_t>(whole.bonds.size()));
}

// Which rank's slice holds an id, and where the ids stop ascending across slices (IdSlices, shared by the
// sliced start-up and the sliced restart). Rank r holds ids 10r + 1 .. 10r + 5 (rank 1 none when there are
// more than two ranks: an empty slice between others).
TEST(IdSlices, RoutesIdsByTheSlicesRanges) {
  const Comm comm(MPI_COMM_WORLD);
  const int r = comm.rank(), p = comm.size();
  const auto empty = [&](int q) { return q == 1 && p > 2; };
  const std::vector<std::int64_t> mine =
      empty(r) ? std::vector<std::int64_t>{} : std::vector<std::int64_t>{10 * r + 1, 10 * r + 5};
  const IdSlices s(comm, mine);
  for (int q = 0; q < p; ++q) {
    EXPECT_EQ(s.slice_of(10 * q + 1), empty(q) ? -1 : q) << q;
    EXPECT_EQ(s.slice_of(10 * q + 3), empty(q) ? -1 : q) << q;  // inside the range: the slice holds it
    EXPECT_EQ(s.slice_of(10 * q + 7), -1) << q;                 // between two slices' ranges
  }
  EXPECT_EQ(s.slice_of(0), -1);
  EXPECT_EQ(s.slice_of(10 * p + 1), -1);
  EXPECT_EQ(s.slice_of(std::numeric_limits<std::int64_t>::max()), -1);
  EXPECT_EQ(s.first(), 1);
  EXPECT_EQ(s.last(), 10 * (p - 1) + 5);
  EXPECT_FALSE(s.disorder());
}

TEST(IdSlices, FindsTheFirstSliceOutOfOrder) {
  const Comm comm(MPI_COMM_WORLD);
  const int r = comm.rank(), p = comm.size();
  // Descending slices: the second non-empty slice comes too early.
  const IdSlices down(comm, {100 - 10 * r, 105 - 10 * r});
  // Overlapping by one id: slice r starts with the last id of slice r - 1.
  const IdSlices dup(comm, {4 * r, 4 * r + 1, 4 * r + 4});
  // Rank 1 empty (p > 2): the check skips it and compares rank 2 with rank 0.
  const bool skip = r == 1 && p > 2;
  const IdSlices gap(comm, skip ? std::vector<std::int64_t>{} : std::vector<std::int64_t>{50 - 10 * r});
  if (p == 1) {
    EXPECT_FALSE(down.disorder());
    EXPECT_FALSE(dup.disorder());
    EXPECT_FALSE(gap.disorder());
    return;
  }
  const auto d = down.disorder();
  ASSERT_TRUE(d);
  EXPECT_EQ(d->rank, 1);
  EXPECT_EQ(d->id, 90);
  EXPECT_EQ(d->previous_rank, 0);
  EXPECT_EQ(d->previous, 105);
  const auto e = dup.disorder();
  ASSERT_TRUE(e);
  EXPECT_EQ(e->rank, 1);
  EXPECT_EQ(e->id, 4);
  EXPECT_EQ(e->previous, 4);  // the same id in two slices: a duplicate
  const auto g = gap.disorder();
  ASSERT_TRUE(g);
  EXPECT_EQ(g->rank, p > 2 ? 2 : 1);
  EXPECT_EQ(g->previous_rank, 0);
  EXPECT_EQ(g->id, p > 2 ? 30 : 40);
  EXPECT_EQ(g->previous, 50);
}
