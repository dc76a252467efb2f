// partition_study replays the solver's decomposition and ghost exchange serially; here the real
// Decomposition and Halo run on cube1.geo at np 1, 2, 4 and every rank checks that the replay gives it
// the same region, the same owned particles and the same ghost ids.
#include "partition_study.hpp"

#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <limits>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/parallel/decomposition.hpp"
#include "basalt/solver/parallel/halo.hpp"
#include "test_support.hpp"

namespace {

using basalt::solver::Comm;
using basalt::solver::Decomposition;
using basalt::solver::Halo;
using basalt::solver::Particles;

void check_grid(const basalt::io::Geometry& g, std::array<int, 3> dims) {
  const auto cloud = basalt::bench::cloud_from_geometry(g);
  // Simulation::distribute: bounding box of the spheres, ghost width with contacts and skin 0.1.
  const double width = basalt::bench::ghost_width(cloud.rmax, cloud.longest_bond, true, 0.1);
  Decomposition dec(Comm(basalt::test::world()), dims, cloud.box_min, cloud.box_max);
  for (int d = 0; d < 3; ++d) {
    const auto [lo, hi] =
        basalt::bench::region_bounds(dec.coords()[d], dec.dims()[d], cloud.box_min[d], cloud.box_max[d]);
    EXPECT_EQ(lo, dec.lo(d));
    EXPECT_EQ(hi, dec.hi(d));
  }
  EXPECT_EQ(basalt::bench::cart_rank(dec.coords(), dec.dims()), dec.comm().rank());

  Particles<double> p;
  std::vector<std::int64_t> owned_ids;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const auto& x = g.position[i];
    std::array<int, 3> c{};
    for (int d = 0; d < 3; ++d)
      c[d] = basalt::bench::region_coord(x[d], dec.dims()[d], cloud.box_min[d], cloud.box_max[d]);
    EXPECT_EQ(c == dec.coords(), dec.owns(x[0], x[1], x[2])) << "particle id " << g.id[i];
    if (!dec.owns(x[0], x[1], x[2])) continue;
    p.push_owned(g.id[i], x[0], x[1], x[2], g.radius[i], g.tag[i], 1.0);
    owned_ids.push_back(g.id[i]);
  }
  Halo<double> halo(dec);
  halo.build_ghosts(p, width);
  std::vector<std::int64_t> real_ghosts(p.id.begin() + static_cast<std::ptrdiff_t>(p.n_owned), p.id.end());
  std::sort(real_ghosts.begin(), real_ghosts.end());

  const auto replay = basalt::bench::partition(cloud, dec.dims(), width, true);
  const auto& mine = replay.sub[static_cast<std::size_t>(dec.comm().rank())];
  EXPECT_EQ(mine.owned, owned_ids.size());
  EXPECT_EQ(mine.ghosts, p.n_ghost());
  std::vector<std::int64_t> replay_ghosts;
  for (auto i : replay.ghost_index[static_cast<std::size_t>(dec.comm().rank())])
    replay_ghosts.push_back(g.id[i]);
  std::sort(replay_ghosts.begin(), replay_ghosts.end());
  EXPECT_EQ(replay_ghosts, real_ghosts);
  if (dec.comm().size() > 1) {
    EXPECT_GT(real_ghosts.size(), 0u);  // a face is shared: the comparison means something
  }
  // Every ghost record the replay sends is received somewhere.
  std::uint64_t sent = 0, ghosts = 0;
  for (const auto& s : replay.sub) {
    sent += s.sent;
    ghosts += s.ghosts;
  }
  EXPECT_EQ(sent, ghosts);
}

const basalt::io::Geometry& cube1() {
  static const auto g = basalt::io::read_geometry(basalt::test::reference_dir() / "cube1.geo");
  return g;
}

TEST(PartitionStudy, ReplayMatchesRealHaloWithMpiDims) { check_grid(cube1(), {0, 0, 0}); }

TEST(PartitionStudy, ReplayMatchesRealHaloAlongOneAxis) {
  // All ranks along x: with 4 ranks the inner slabs (3.75 mm) are narrower than two ghost widths, so
  // some particles go to both neighbours.
  check_grid(cube1(), {basalt::test::size(), 1, 1});
}

TEST(PartitionStudy, ReplayMatchesRealHaloAlongZ) { check_grid(cube1(), {1, 1, basalt::test::size()}); }

}  // namespace
