// Frame pieces: the flat wire format round-trips exactly and rejects damaged buffers;
// assembling pieces sorts particles and bonds by id and refuses duplicates.
#include <gtest/gtest.h>

#include "basalt/io/frame.hpp"

using namespace basalt::io;

namespace {
FramePiece make_piece(int rank, int n, std::int64_t step) {
  FramePiece p;
  p.kinds = kFrameCheckpoint;
  p.step = step;
  p.time = step * 1e-3;
  p.dt = 1e-3;
  p.source_rank = rank;
  for (int k = 0; k < n; ++k) {
    const std::int64_t id = 100 - (rank + 2 * k);  // descending on purpose
    p.id.push_back(id);
    p.position.push_back({double(id), 0.5 * id, -1.0 / (id + 1)});
    p.velocity.push_back({0.1 * id, 0, 1});
    p.radius.push_back(0.2 + 0.001 * id);
    p.mass.push_back(1.5 * id + 1);
    p.tag.push_back(id % 3);
  }
  p.bonds.push_back({p.id[0], p.id[1], 7});
  p.bond_rest_length.push_back(0.75);
  p.bond_broken.push_back(rank == 1);
  if (rank == 0) p.walls.push_back({"base", {0, 0, 0.1}, {0, 0, 1}, {0, 0, 0.05}, {0, 0, 3.5}});
  return p;
}
}  // namespace

TEST(Frame, RoundTripIsExact) {
  const auto p = make_piece(0, 5, 42);
  std::vector<std::byte> bytes;
  serialize(p, bytes);
  const auto q = deserialize(bytes);
  EXPECT_EQ(q.step, 42);
  EXPECT_EQ(q.time, p.time);
  EXPECT_EQ(q.id, p.id);
  EXPECT_EQ(q.position, p.position);
  EXPECT_EQ(q.velocity, p.velocity);
  EXPECT_EQ(q.radius, p.radius);
  EXPECT_EQ(q.mass, p.mass);
  EXPECT_EQ(q.tag, p.tag);
  EXPECT_EQ(q.bonds, p.bonds);
  EXPECT_EQ(q.bond_rest_length, p.bond_rest_length);
  ASSERT_EQ(q.walls.size(), 1u);
  EXPECT_EQ(q.walls[0].name, "base");
  EXPECT_EQ(q.walls[0].force, p.walls[0].force);
  EXPECT_TRUE(q.position_at_rebuild.empty());
  EXPECT_EQ(q.rebuild_step, -1);
}

TEST(Frame, PositionsAtRebuildTravelAndAssemble) {
  // The state a restart replays the last neighbour-list rebuild from: exact, following the ids.
  std::vector<FramePiece> pieces{make_piece(1, 4, 7), make_piece(0, 4, 7)};
  for (auto& p : pieces) {
    for (const auto id : p.id) p.position_at_rebuild.push_back({double(id) + 1e-17, 0.25 * id, 1.0 / 3});
    p.rebuild_step = 3;
  }
  pieces[1].rebuild_pending = 1;
  std::vector<std::byte> bytes;
  serialize(pieces[0], bytes);
  const auto q = deserialize(bytes);
  EXPECT_EQ(q.position_at_rebuild, pieces[0].position_at_rebuild);
  EXPECT_EQ(q.rebuild_step, 3);
  EXPECT_EQ(q.rebuild_pending, 0);
  const auto c = assemble(pieces, RunInfo{});
  ASSERT_EQ(c.position_at_rebuild.size(), c.size());
  for (std::size_t i = 0; i < c.size(); ++i) EXPECT_EQ(c.position_at_rebuild[i][1], 0.25 * c.geometry.id[i]);
  EXPECT_EQ(c.rebuild_step, 3);
  EXPECT_TRUE(c.rebuild_pending);  // any rank's pending rebuild is everyone's
  // A piece without them (or another rebuild step): the checkpoint has none.
  pieces[0].position_at_rebuild.clear();
  EXPECT_TRUE(assemble(pieces, RunInfo{}).position_at_rebuild.empty());
  // Lengths that differ from the particles' are refused on arrival.
  pieces[1].position_at_rebuild.pop_back();
  serialize(pieces[1], bytes);
  EXPECT_THROW(deserialize(bytes), std::runtime_error);
}

TEST(Frame, DamagedBuffersAreRejected) {
  std::vector<std::byte> bytes;
  serialize(make_piece(0, 5, 1), bytes);
  auto truncated = bytes;
  truncated.resize(bytes.size() - 9);
  EXPECT_THROW(deserialize(truncated), std::runtime_error);
  auto bad_magic = bytes;
  bad_magic[0] = std::byte{0};
  EXPECT_THROW(deserialize(bad_magic), std::runtime_error);
  auto trailing = bytes;
  trailing.push_back(std::byte{1});
  EXPECT_THROW(deserialize(trailing), std::runtime_error);
}

TEST(Frame, AssembleSortsByIdAndKeepsState) {
  std::vector<FramePiece> pieces{make_piece(1, 4, 7), make_piece(0, 4, 7)};
  RunInfo info;
  info.box_max = {15, 15, 15};
  info.scene_text = "dt = 1e-3";
  const auto c = assemble(pieces, info);
  ASSERT_EQ(c.size(), 8u);
  EXPECT_TRUE(std::is_sorted(c.geometry.id.begin(), c.geometry.id.end()));
  for (std::size_t i = 0; i < c.size(); ++i) {
    const auto id = c.geometry.id[i];
    EXPECT_EQ(c.geometry.position[i][0], double(id));
    EXPECT_EQ(c.velocity[i][0], 0.1 * id);
    EXPECT_EQ(c.geometry.mass[i], 1.5 * id + 1);
  }
  ASSERT_EQ(c.geometry.bonds.size(), 2u);
  EXPECT_LT(c.geometry.bonds[0].a, c.geometry.bonds[0].b);
  EXPECT_EQ(c.walls.size(), 1u);
  EXPECT_EQ(c.step, 7);
  EXPECT_EQ(c.scene_text, "dt = 1e-3");
  EXPECT_EQ(c.geometry.box_max[2], 15);
}

TEST(Frame, AssembleRefusesDuplicateIdsAndMixedSteps) {
  std::vector<FramePiece> dup{make_piece(0, 3, 5), make_piece(0, 3, 5)};
  EXPECT_THROW(assemble(dup, RunInfo{}), std::runtime_error);
  std::vector<FramePiece> mixed{make_piece(0, 3, 5), make_piece(1, 3, 6)};
  EXPECT_THROW(assemble(mixed, RunInfo{}), std::runtime_error);
}
