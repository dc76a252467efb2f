// Frame pieces: the flat wire format round-trips exactly and rejects damaged buffers; the frame
// writer converts columns exactly and refuses frames not filled exactly; assembling pieces sorts
// particles and bonds by id and refuses duplicates.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "basalt/io/frame.hpp"

using namespace basalt::io;

namespace {
FramePiece make_piece(int rank, int n, std::int64_t step) {
  FramePiece p;
  p.kinds = kFrameCheckpoint;
  p.step = step;
  p.time = step * 1e-3;
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
  if (rank == 0)
    p.walls.push_back({"base", {0, 0, 0.1}, {0, 0, 1}, {0, 0, 0.05}, {0, 0, 3.5}, {0.25, -1.0, 0.1}});
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
  EXPECT_EQ(q.walls[0].motion_state, p.walls[0].motion_state);
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
  // Lengths that differ from the particles' cannot be put on the wire (the header has one count).
  pieces[1].position_at_rebuild.pop_back();
  EXPECT_THROW(serialize(pieces[1], bytes), std::invalid_argument);
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
  info.dt = 1e-3;
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
  EXPECT_EQ(c.dt, 1e-3);  // from the run's information, not from the frames
  EXPECT_EQ(c.geometry.box_max[2], 15);
}

TEST(Frame, FrameAttributesTravelAndOverrideTheRunsInTheCheckpoint) {
  // The decomposition's cuts change during a run: one piece carries them per frame, and they replace
  // the value the run's information had at its start.
  std::vector<FramePiece> pieces{make_piece(0, 4, 7), make_piece(1, 4, 7)};
  pieces[0].attributes["decomposition_cuts"] = "7.25;;";
  std::vector<std::byte> bytes;
  serialize(pieces[0], bytes);
  const auto back = deserialize(bytes);
  EXPECT_EQ(back.attributes, pieces[0].attributes);
  serialize(pieces[1], bytes);
  EXPECT_TRUE(deserialize(bytes).attributes.empty());
  bytes.resize(bytes.size() - sizeof(std::uint64_t));  // a frame that ends after its fields (older writer)
  EXPECT_TRUE(deserialize(bytes).attributes.empty());
  RunInfo info;
  info.attributes = {{"decomposition_cuts", "7.5;;"}, {"ghost_width", "1.1"}};
  pieces[0] = back;
  const auto c = assemble(pieces, info);
  EXPECT_EQ(c.geometry.attributes.at("decomposition_cuts"), "7.25;;");
  EXPECT_EQ(c.geometry.attributes.at("ghost_width"), "1.1");
}

TEST(Frame, RunInfoRoundTripsWithTheTimeStep) {
  // Sent once at start: what is constant for the run, dt included (frames do not carry it).
  RunInfo info;
  info.dt = 1.0 / 3.0 * 1e-3;
  info.box_min = {-1, -2, -3};
  info.box_max = {15, 15, 15.5};
  info.periodic = {true, false, true};
  info.units.length = "mm";
  info.attributes["code_version"] = "test";
  info.scene_text = "[run]\ndt = 1e-3\n";
  std::vector<std::byte> bytes;
  serialize(info, bytes);
  const RunInfo back = deserialize_run_info(bytes);
  EXPECT_EQ(back.dt, info.dt);
  EXPECT_EQ(back.box_min, info.box_min);
  EXPECT_EQ(back.box_max, info.box_max);
  EXPECT_EQ(back.periodic, info.periodic);
  EXPECT_EQ(back.units.length, "mm");
  EXPECT_EQ(back.attributes, info.attributes);
  EXPECT_EQ(back.scene_text, info.scene_text);
  bytes[0] = std::byte{0};
  EXPECT_THROW(deserialize_run_info(bytes), std::runtime_error);
}

TEST(Frame, AssembleRefusesDuplicateIdsAndMixedSteps) {
  std::vector<FramePiece> dup{make_piece(0, 3, 5), make_piece(0, 3, 5)};
  EXPECT_THROW(assemble(dup, RunInfo{}), std::runtime_error);
  std::vector<FramePiece> mixed{make_piece(0, 3, 5), make_piece(1, 3, 6)};
  EXPECT_THROW(assemble(mixed, RunInfo{}), std::runtime_error);
}

TEST(Frame, InverseMassesTravelAndMassesAreDerivedOnArrival) {
  auto p = make_piece(0, 6, 3);
  p.inv_mass.clear();
  for (const auto id : p.id) p.inv_mass.push_back(1.0 / (0.3 * double(id) + 0.7));
  p.mass.assign(p.size(), -1.0);  // not sent: the reader derives it
  std::vector<std::byte> bytes;
  serialize(p, bytes);
  const auto q = deserialize(bytes);
  ASSERT_EQ(q.inv_mass, p.inv_mass);
  ASSERT_EQ(q.mass.size(), p.size());
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_EQ(q.mass[i], 1.0 / p.inv_mass[i]);
}

namespace {
FrameHeader small_header(std::uint64_t n, std::uint64_t m) {
  FrameHeader h;
  h.kinds = kFrameVtk;
  h.step = 9;
  h.particles = n;
  h.bonds = m;
  return h;
}
/// Fills every column of a frame of n particles and m bonds from float and narrow arrays.
void fill_all(FrameWriter& w, std::size_t n, std::size_t m) {
  std::vector<float> f(n);
  std::vector<std::int64_t> id(n);
  std::vector<std::int32_t> tag(n, 2);
  for (std::size_t i = 0; i < n; ++i) {
    f[i] = 0.1f * float(i + 1);
    id[i] = std::int64_t(10 * i);
  }
  w.column(Column::id, id);
  w.column(Column::tag, tag);
  for (auto c :
       {Column::x, Column::y, Column::z, Column::vx, Column::vy, Column::vz, Column::radius, Column::mass})
    w.column(c, f);
  const std::vector<std::uint8_t> group(m, 3);
  for (std::size_t k = 0; k < m; ++k) {
    w.set(Column::bond_a, k, id[0]);
    w.set(Column::bond_b, k, id[1]);
  }
  w.column(Column::bond_group, group);
  w.fill(Column::bond_rest_length, 0, m, 0.5f);
  w.fill(Column::bond_broken, 0, m, 1);
}
}  // namespace

TEST(FrameWriter, FloatColumnsWidenExactly) {
  std::vector<std::byte> bytes;
  FrameWriter w(bytes, small_header(4, 2));
  fill_all(w, 4, 2);
  const auto size = w.finish();  // completes the frame (its attribute count): the size after it
  EXPECT_EQ(size, bytes.size());
  const auto q = deserialize(bytes);
  ASSERT_EQ(q.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const double want = double(0.1f * float(i + 1));  // the float's value, not 0.1 * (i + 1)
    EXPECT_EQ(q.position[i][2], want);
    EXPECT_EQ(q.velocity[i][0], want);
    EXPECT_EQ(q.inv_mass[i], want);
    EXPECT_EQ(q.mass[i], 1.0 / want);
    EXPECT_EQ(q.id[i], std::int64_t(10 * i));
    EXPECT_EQ(q.tag[i], 2);
  }
  ASSERT_EQ(q.bonds.size(), 2u);
  EXPECT_EQ(q.bonds[1], (Bond{0, 10, 3}));
  EXPECT_EQ(q.bond_rest_length[1], 0.5);
  EXPECT_EQ(q.bond_broken[0], 1);
  EXPECT_TRUE(q.position_at_rebuild.empty());
  EXPECT_TRUE(q.walls.empty());
}

TEST(FrameWriter, RecycledBufferIsOverwrittenNotAppended) {
  // The output client reuses its send buffers without clearing them.
  std::vector<std::byte> bytes(100000, std::byte{0xAB});
  {
    FrameWriter w(bytes, small_header(3, 1));
    fill_all(w, 3, 1);
    w.wall({"base", {0, 0, 1}, {0, 0, 1}, {0, 0, 2}, {0, 0, 3}, {}});
    w.finish();
  }
  const auto q = deserialize(bytes);
  EXPECT_EQ(q.size(), 3u);
  ASSERT_EQ(q.walls.size(), 1u);
  EXPECT_EQ(q.walls[0].name, "base");
  EXPECT_EQ(q.walls[0].force[2], 3.0);
}

TEST(FrameWriter, FramesNotFilledExactlyAreRefused) {
  std::vector<std::byte> bytes;
  {
    FrameWriter w(bytes, small_header(4, 2));
    fill_all(w, 4, 2);
    w.set(Column::bond_broken, 1, 0);  // one entry twice
    EXPECT_THROW(w.finish(), std::logic_error);
  }
  {
    FrameWriter w(bytes, small_header(4, 2));
    fill_all(w, 3, 2);  // particle columns one short
    EXPECT_THROW(w.finish(), std::logic_error);
  }
  FrameWriter w(bytes, small_header(4, 2));
  const std::vector<double> five(5, 1.0);
  EXPECT_THROW(w.column(Column::x, five), std::out_of_range);
  EXPECT_THROW(w.set(Column::bond_a, 2, 1), std::out_of_range);
  EXPECT_THROW(w.column(Column::x_rebuild, std::vector<double>{}, 1), std::out_of_range);  // absent column
}

TEST(Frame, ImpossibleCountsAreRejected) {
  std::vector<std::byte> bytes;
  serialize(make_piece(0, 5, 1), bytes);
  auto huge = bytes;  // particle count (bytes 40-47 of the header) far beyond the buffer
  const std::uint64_t n = std::numeric_limits<std::uint64_t>::max() / 4;
  std::memcpy(huge.data() + 40, &n, sizeof(n));
  EXPECT_THROW(deserialize(huge), std::runtime_error);
  auto more = bytes;  // one particle more than the buffer holds
  const std::uint64_t six = 6;
  std::memcpy(more.data() + 40, &six, sizeof(six));
  EXPECT_THROW(deserialize(more), std::runtime_error);
}

TEST(Frame, ParticleFieldsAndContactsTravelAndAssemble) {
  std::vector<FramePiece> pieces{make_piece(1, 4, 7), make_piece(0, 3, 7)};
  for (auto& p : pieces) {
    std::vector<double> v;
    for (const auto id : p.id) v.push_back(0.5 * double(id));
    p.fields.emplace_back("bonds_broken", v);
    p.contact_width = 1;
    p.contact_ids.push_back({p.id[1], p.id[0]});
    p.contact_model.push_back(0);
    p.contact_history.push_back(double(p.source_rank) + 0.25);
  }
  std::vector<FramePiece> back;
  for (const auto& p : pieces) {
    std::vector<std::byte> bytes;
    serialize(p, bytes);
    back.push_back(deserialize(bytes));
    EXPECT_EQ(back.back().fields, p.fields);
    EXPECT_EQ(back.back().contact_ids, p.contact_ids);
    EXPECT_EQ(back.back().contact_history, p.contact_history);
  }
  RunInfo info;
  const auto c = assemble(back, info);
  ASSERT_EQ(c.particle_fields.size(), 1u);
  for (std::size_t i = 0; i < c.size(); ++i)
    EXPECT_EQ(c.particle_fields[0].second[i], 0.5 * double(c.geometry.id[i]));
  ASSERT_EQ(c.contact_ids.size(), 2u);  // sorted by (model, lower id, higher id)
  EXPECT_LT(std::min(c.contact_ids[0][0], c.contact_ids[0][1]),
            std::min(c.contact_ids[1][0], c.contact_ids[1][1]));
  // A piece that lacks a field the others have cannot be assembled.
  back[0].fields.clear();
  EXPECT_THROW(assemble(back, info), std::runtime_error);
}

TEST(Frame, BreakPositionsTravelAndAssembleWithTheirBonds) {
  // Piece 1 holds a broken bond (and where it broke); piece 0 an intact bond and a broken one whose
  // position is not known (NaN). Assembled, the rows follow the bonds' (a, b) order.
  auto p0 = make_piece(0, 3, 7), p1 = make_piece(1, 3, 7);
  p1.bond_break_position = {{1.25, -2.5, 3.0000000000000004}};
  p0.bonds.push_back({p0.id[1], p0.id[2], 7});
  p0.bond_rest_length.push_back(1.0);
  p0.bond_broken.push_back(2 | (2 << 2));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  p0.bond_break_position = {{nan, nan, nan}};
  std::vector<FramePiece> pieces;
  for (const auto* p : {&p0, &p1}) {
    std::vector<std::byte> bytes;
    serialize(*p, bytes);
    pieces.push_back(deserialize(bytes));
  }
  ASSERT_EQ(pieces[0].bond_break_position.size(), 1u);
  EXPECT_TRUE(std::isnan(pieces[0].bond_break_position[0][0]));
  ASSERT_EQ(pieces[1].bond_break_position.size(), 1u);
  EXPECT_EQ(pieces[1].bond_break_position[0], p1.bond_break_position[0]);
  const Checkpoint c = assemble(pieces, RunInfo{});
  ASSERT_EQ(c.bond_broken.size(), 3u);
  // Bonds sorted by (a, b): piece 0's (96, 98), piece 1's (97, 99), piece 0's (98, 100).
  EXPECT_EQ(c.bond_broken, (std::vector<std::uint8_t>{2 | (2 << 2), 1, 0}));
  ASSERT_EQ(c.bond_break_position.size(), 2u);
  EXPECT_TRUE(std::isnan(c.bond_break_position[0][1]));
  EXPECT_EQ(c.bond_break_position[1], p1.bond_break_position[0]);

  // A piece whose break positions do not match its broken bonds is refused before it is sent.
  p1.bond_break_position.push_back({0, 0, 0});
  std::vector<std::byte> bytes;
  EXPECT_THROW(serialize(p1, bytes), std::invalid_argument);
}
