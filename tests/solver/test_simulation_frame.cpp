// A compute rank's frame written straight into a byte buffer (SimulationFrame through
// io::FrameWriter) and read back as the I/O rank reads it (io::deserialize) equals the solver's
// own state: owned particles exactly (float runs widened exactly), masses derived from the
// inverse masses, positions at the last rebuild, every bond once across the ranks (broken ones
// flagged), the walls on rank 0 only.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <sstream>
#include <utility>

#include "basalt/io/frame.hpp"
#include "basalt/solver/output/simulation_frame.hpp"
#include "basalt/solver/simulation.hpp"
#include "geometries.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace basalt;
using namespace basalt::solver;

namespace {

/// The wave scene with breakable bonds (break_strain 2 %), so that a kicked particle breaks some,
/// and checkpoints.
Scene breakable_wave_scene() {
  const auto file = test::source_dir() / "scenes" / "wave.toml";
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  const std::string key = "rest_length = \"initial_distance\"\n";
  const auto at = s.find(key);
  EXPECT_NE(at, std::string::npos) << "scenes/wave.toml changed: update this test";
  s.insert(at + key.size(), "break_strain = 0.02\n");
  auto scene = parse_scene_text(s, file.string(), file.parent_path());
  scene.checkpoint_every = 100;  // the solver keeps the positions at rebuild only for checkpoints
  return scene;
}

/// All ranks' values, on rank 0 (empty elsewhere).
std::vector<std::int64_t> gather(const std::vector<std::int64_t>& mine) {
  const int n = static_cast<int>(mine.size()), size = test::size();
  std::vector<int> counts(size), displs(size);
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, test::world());
  std::exclusive_scan(counts.begin(), counts.end(), displs.begin(), 0);
  std::vector<std::int64_t> all(test::rank() == 0 ? displs.back() + counts.back() : 0);
  MPI_Gatherv(mine.data(), n, MPI_INT64_T, all.data(), counts.data(), displs.data(), MPI_INT64_T, 0,
              test::world());
  return all;
}

template <class Real>
void check_frame_equals_state() {
  const auto scene = breakable_wave_scene();
  const auto g = test::cube1();
  auto opt = test::quiet();
  opt.force_dt = true;
  Simulation<Real> sim(scene, g, test::world(), opt);
  // Kick the particle with the lowest id hard: its bonds break within a few steps.
  auto& p = sim.particles();
  for (std::size_t i = 0; i < p.n_owned; ++i)
    if (p.id[i] == g.id.front()) p.vx[i] = Real(50);
  sim.state_changed();
  sim.run(40);
  const auto broken_total = sim.comm().sum(static_cast<long long>(sim.broken_bonds().size()));
  EXPECT_GT(broken_total, 0) << "the kick should have broken bonds";

  std::vector<std::byte> bytes(3, std::byte{0x5A});  // a recycled buffer: not cleared first
  const SimulationFrame<Real> frame(sim, io::kFrameCheckpoint);
  const auto size = io::serialize(frame, bytes);
  EXPECT_EQ(size, bytes.size());
  const auto q = io::deserialize(bytes);

  const auto& s = sim.particles();
  const std::size_t n = s.n_owned;
  EXPECT_EQ(q.kinds, io::kFrameCheckpoint);
  EXPECT_EQ(q.step, sim.current_step());
  EXPECT_EQ(q.time, sim.time());
  EXPECT_EQ(q.source_rank, test::rank());
  ASSERT_EQ(q.size(), n);
  ASSERT_EQ(q.inv_mass.size(), n);
  ASSERT_EQ(q.position_at_rebuild.size(), n);
  EXPECT_EQ(q.rebuild_step, sim.last_rebuild_step());
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double inv = double(s.inv_mass[i]);
    const bool same = q.id[i] == s.id[i] && q.tag[i] == s.tag[i] && q.position[i][0] == double(s.x[i]) &&
                      q.position[i][1] == double(s.y[i]) && q.position[i][2] == double(s.z[i]) &&
                      q.velocity[i][0] == double(s.vx[i]) && q.velocity[i][1] == double(s.vy[i]) &&
                      q.velocity[i][2] == double(s.vz[i]) && q.radius[i] == double(s.radius[i]) &&
                      q.inv_mass[i] == inv && q.mass[i] == 1.0 / inv;
    wrong += same ? 0 : 1;
  }
  EXPECT_EQ(wrong, 0u) << "of " << n << " owned particles differ from the solver's";
  // Positions at the last rebuild are near the positions now (within the skin), not equal to them
  // after particles moved; a restart needs them exactly, checked by io_e2e.restart_*.
  double max_gap = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d)
      max_gap = std::max(max_gap, std::abs(q.position_at_rebuild[i][d] - q.position[i][d]));
  EXPECT_LT(max_gap, scene.skin);

  // Bonds: each geometry bond exactly once across the ranks, the broken ones flagged.
  std::vector<std::int64_t> pairs, flags;
  for (std::size_t k = 0; k < q.bonds.size(); ++k) {
    pairs.push_back(std::min(q.bonds[k].a, q.bonds[k].b));
    pairs.push_back(std::max(q.bonds[k].a, q.bonds[k].b));
    flags.push_back(q.bond_broken[k]);
    EXPECT_GT(q.bond_rest_length[k], 0.0);
  }
  // Where each broken bond broke travels with it: the solver's break record (the contact point of the
  // two spheres at the break), one row per broken bond, in the order of the broken bonds.
  const auto& records = sim.broken_bonds();
  EXPECT_EQ(q.bond_break_position.size(), records.size());
  std::size_t misplaced = 0, row = 0;
  for (std::size_t k = 0; k < q.bonds.size() && row < records.size(); ++k) {
    if (q.bond_broken[k] == 0) continue;
    const auto& r = records[row];
    const auto& x = q.bond_break_position[row++];
    const bool same = q.bonds[k].a == r.a && q.bonds[k].b == r.b && x[0] == r.x && x[1] == r.y &&
                      x[2] == r.z && std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
    misplaced += same ? 0 : 1;
  }
  EXPECT_EQ(misplaced, 0u) << "of " << records.size() << " break positions are not the solver's records";
  const auto all_pairs = gather(pairs);
  const auto all_flags = gather(flags);
  std::size_t walls = q.walls.size();
  if (test::rank() == 0) {
    std::vector<std::pair<std::int64_t, std::int64_t>> got, want;
    for (std::size_t k = 0; k < all_pairs.size(); k += 2) got.push_back({all_pairs[k], all_pairs[k + 1]});
    for (const auto& b : g.bonds) want.push_back({std::min(b.a, b.b), std::max(b.a, b.b)});
    std::sort(got.begin(), got.end());
    std::sort(want.begin(), want.end());
    EXPECT_EQ(got.size(), want.size());
    EXPECT_TRUE(got == want) << "the frames' bonds are not the geometry's, each once";
    EXPECT_EQ(std::count(all_flags.begin(), all_flags.end(), 1), broken_total);
    EXPECT_EQ(walls, scene.walls.size());
    if (!q.walls.empty()) {
      EXPECT_EQ(q.walls[0].name, "base");
    }
  } else {
    EXPECT_EQ(walls, 0u) << "walls travel with compute rank 0's frame only";
  }

  // A VTK-only frame has no positions at rebuild; the same (now larger) buffer is reused.
  io::serialize(SimulationFrame<Real>(sim, io::kFrameVtk), bytes);
  const auto v = io::deserialize(bytes);
  EXPECT_EQ(v.kinds, io::kFrameVtk);
  EXPECT_TRUE(v.position_at_rebuild.empty());
  EXPECT_EQ(v.id, q.id);
  EXPECT_EQ(v.position, q.position);
  EXPECT_EQ(v.bonds, q.bonds);
}

}  // namespace

TEST(SimulationFrame, DoubleFrameEqualsTheSolverState) { check_frame_equals_state<double>(); }
TEST(SimulationFrame, FloatFrameEqualsTheSolverState) { check_frame_equals_state<float>(); }
