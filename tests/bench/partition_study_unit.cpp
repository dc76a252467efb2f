// partition_study without MPI ranks: region arithmetic, tiling and the counts it must give.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "basalt/io/geometry.hpp"
#include "partition_study.hpp"
#include "test_support.hpp"

namespace {

using basalt::bench::Cloud;

TEST(PartitionStudyUnit, RegionsCoverTheLineAndAgreeWithCoord) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(basalt::bench::region_bounds(0, 3, 0.0, 30.0), std::make_pair(-inf, 10.0));
  EXPECT_EQ(basalt::bench::region_bounds(1, 3, 0.0, 30.0), std::make_pair(10.0, 20.0));
  EXPECT_EQ(basalt::bench::region_bounds(2, 3, 0.0, 30.0), std::make_pair(20.0, inf));
  for (double v : {-5.0, 0.0, 9.999, 10.0, 19.99, 20.0, 45.0}) {
    const int c = basalt::bench::region_coord(v, 3, 0.0, 30.0);
    const auto [lo, hi] = basalt::bench::region_bounds(c, 3, 0.0, 30.0);
    EXPECT_TRUE(v >= lo && v < hi) << v;
  }
  EXPECT_EQ(basalt::bench::ghost_width(1.0, 1.5, true, 0.1), 2.1);
  EXPECT_EQ(basalt::bench::ghost_width(1.0, 1.5, false, 0.1), 1.6);
  EXPECT_EQ(basalt::bench::cart_rank({1, 2, 3}, {2, 3, 4}), (1 * 3 + 2) * 4 + 3);
}

TEST(PartitionStudyUnit, HandMadeLineOfParticles) {
  // Four particles on the x axis in a box [0, 4): two slabs cut at 2, ghost width 0.6.
  Cloud c;
  c.x = {0.5, 1.5, 2.2, 3.5};
  c.y = {0.5, 0.5, 0.5, 0.5};
  c.z = {0.5, 0.5, 0.5, 0.5};
  c.box_min = {0, 0, 0};
  c.box_max = {4, 1, 1};
  c.bonds = {{0, 1}, {1, 2}, {2, 3}};
  c.bond_stride = 4;
  const auto r = basalt::bench::partition(c, {2, 1, 1}, 0.6, true);
  ASSERT_EQ(r.sub.size(), 2u);
  EXPECT_EQ(r.sub[0].owned, 2u);
  EXPECT_EQ(r.sub[1].owned, 2u);
  EXPECT_EQ(r.ghost_index[0], (std::vector<std::uint32_t>{2}));  // 2.2 < 2 + 0.6
  EXPECT_EQ(r.ghost_index[1], (std::vector<std::uint32_t>{1}));  // 1.5 >= 2 - 0.6
  EXPECT_EQ(r.sub[0].sent, 1u);
  EXPECT_EQ(r.sub[0].messages, 1);
  EXPECT_EQ(r.crossing_bonds, 1u);
  EXPECT_EQ(r.sub[0].crossing_bonds, 1u);
}

TEST(PartitionStudyUnit, CornerGhostsArriveByForwarding) {
  // One particle near the corner of four regions (2 x 2 x 1) reaches the three others: two directly,
  // the diagonal one through forwarding along y.
  Cloud c;
  c.x = {1.9, 0.1, 3.9};
  c.y = {1.9, 0.1, 3.9};
  c.z = {0.5, 0.5, 0.5};
  c.box_min = {0, 0, 0};
  c.box_max = {4, 4, 1};
  const auto r = basalt::bench::partition(c, {2, 2, 1}, 0.5, true);
  EXPECT_EQ(r.sub[0].owned, 2u);
  EXPECT_EQ(r.sub[0].sent, 2u);  // particle 0 along x and along y
  for (int k = 1; k < 4; ++k)
    EXPECT_EQ(r.ghost_index[static_cast<std::size_t>(k)], (std::vector<std::uint32_t>{0}))
        << "subdomain " << k;
  EXPECT_EQ(r.sub[1].sent + r.sub[2].sent, 1u);  // the forwarded copy
}

TEST(PartitionStudyUnit, TiledCubeOwnsOneTilePerSubdomain) {
  const auto base = basalt::bench::load_cloud((basalt::test::reference_dir() / "cube1.geo").string());
  ASSERT_EQ(base.size(), 8948u);
  const auto t = basalt::bench::tile_cloud(base, 2, 15.0);
  EXPECT_EQ(t.size(), 8u * 8948u);
  EXPECT_EQ(t.bond_count(), 8u * base.bond_count());
  const double w = basalt::bench::ghost_width(t.rmax, t.longest_bond, true, 0.1);
  const auto r = basalt::bench::partition(t, {2, 2, 2}, w);
  std::uint64_t sent = 0, ghosts = 0;
  for (const auto& s : r.sub) {
    EXPECT_EQ(s.owned, 8948u);  // cube1 lies in [0, 15]^3, the cuts fall on the tile seams
    EXPECT_EQ(s.messages, 3);   // a corner subdomain has one neighbour per axis
    EXPECT_GT(s.ghosts, 0u);
    sent += s.sent;
    ghosts += s.ghosts;
  }
  EXPECT_EQ(sent, ghosts);
  EXPECT_EQ(r.crossing_bonds, 0u);  // tiles carry no bonds across their seams
}

}  // namespace
