// Checkpoints (schema "basalt-checkpoint" v1): exact round trip, completion mark, refusal of
// other schemas/versions, truncated and .partial files skipped when looking for the latest,
// and errors naming the path when the destination cannot be written.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "basalt/io/checkpoint.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace basalt::io;
using basalt::io::test::expect_format_error;
using basalt::io::test::read_bytes;
using basalt::io::test::write_bytes;

namespace {

// The sample geometry (unsorted ids 40, 3, 17, 8, 99, 5) with a full run state.
Checkpoint sample_checkpoint() {
  Checkpoint c;
  c.geometry = basalt::io::test::sample_geometry();
  c.velocity = {{0.1, 0, 0}, {0, 0.3, 0}, {0, 0, -1e-9}, {1, 2, 3}, {-4, 5, -6}, {7.5e-300, 0, 1}};
  c.bond_rest_length = {0.75, 1.4999999999999998, 0.5, 1.0};
  c.bond_broken = {0, 1, 0, 0};
  c.walls = {{"top", {0, 0, 15}, {0, 0, -1}, {0, 0, 0}, {0, 0, 12.5}, {0.0, 0.1, 14.999999999999998}},
             {"base", {0, 0, 0}, {0, 0, 1}, {0, 0, 0.1}, {0, 0, -3.25}, {}}};
  c.step = 1700;
  c.time = 1.7000000000000002;
  c.dt = 1e-3;
  c.scene_text = "[run]\ndt = 1e-3  # ms\nname = \"cube \u00e9\u00e8\"\n";
  return c;
}

// What a reader must find: particles sorted by id, velocities following them, bonds a < b.
Checkpoint sorted_expected(const Checkpoint& c) {
  Checkpoint e = c;
  e.geometry.sort_by_id();
  for (std::size_t i = 0; i < e.size(); ++i) {
    const auto from =
        std::find(c.geometry.id.begin(), c.geometry.id.end(), e.geometry.id[i]) - c.geometry.id.begin();
    e.velocity[i] = c.velocity[from];
  }
  return e;
}

void expect_same(const Checkpoint& a, const Checkpoint& b) {
  basalt::io::test::expect_same_particles_and_bonds(a.geometry, b.geometry);
  EXPECT_EQ(a.velocity, b.velocity);
  EXPECT_EQ(a.bond_rest_length, b.bond_rest_length);
  EXPECT_EQ(a.bond_broken, b.bond_broken);
  ASSERT_EQ(a.walls.size(), b.walls.size());
  for (std::size_t k = 0; k < a.walls.size(); ++k) {
    EXPECT_EQ(a.walls[k].name, b.walls[k].name);
    EXPECT_EQ(a.walls[k].position, b.walls[k].position);
    EXPECT_EQ(a.walls[k].normal, b.walls[k].normal);
    EXPECT_EQ(a.walls[k].velocity, b.walls[k].velocity);
    EXPECT_EQ(a.walls[k].force, b.walls[k].force);
    EXPECT_EQ(a.walls[k].motion_state, b.walls[k].motion_state);  // a servo wall's, bit for bit
  }
  EXPECT_EQ(a.step, b.step);
  EXPECT_EQ(a.time, b.time);
  EXPECT_EQ(a.dt, b.dt);
  EXPECT_EQ(a.scene_text, b.scene_text);
  EXPECT_EQ(a.geometry.units, b.geometry.units);
  EXPECT_EQ(a.geometry.attributes, b.geometry.attributes);
  EXPECT_EQ(a.geometry.statistics, b.geometry.statistics);
  EXPECT_EQ(a.geometry.box_max, b.geometry.box_max);
  EXPECT_EQ(a.geometry.periodic, b.geometry.periodic);
}

void edit_file(const fs::path& file, const std::function<void(hid_t)>& edit) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  edit(f);
  ASSERT_GE(H5Fclose(f), 0);
}

void set_int_attribute(hid_t f, const char* name, std::int32_t value) {
  if (H5Aexists(f, name) > 0) H5Adelete(f, name);
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t a = H5Acreate2(f, name, H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, H5T_NATIVE_INT32, &value);
  H5Aclose(a);
  H5Sclose(space);
}

}  // namespace

TEST(Checkpoint, RoundTripIsExact) {
  const auto dir = basalt::test::scratch_dir("ckpt-roundtrip");
  const Checkpoint c = sample_checkpoint();
  write_checkpoint(c, dir / "ckpt_1700.h5");
  EXPECT_FALSE(fs::exists(dir / "ckpt_1700.h5.partial"));
  EXPECT_TRUE(is_complete_checkpoint(dir / "ckpt_1700.h5"));
  const Checkpoint back = read_checkpoint(dir / "ckpt_1700.h5");
  expect_same(back, sorted_expected(c));
  EXPECT_EQ(back.walls[0].name, "top");  // walls keep their order, not HDF5's name order
  EXPECT_EQ(back.geometry.id.front(), 3);
  EXPECT_EQ(back.velocity.front(), (Vec3{0, 0.3, 0}));  // the velocity of id 3 followed it

  // Identical state, identical bytes; and the reference packing round-trips too.
  write_checkpoint(c, dir / "again.h5");
  EXPECT_TRUE(read_bytes(dir / "again.h5") == read_bytes(dir / "ckpt_1700.h5"));

  Checkpoint cube;
  cube.geometry = read_geometry(basalt::test::reference_dir() / "cube1.geo");
  const auto n = cube.size();
  for (std::size_t i = 0; i < n; ++i) {
    cube.geometry.mass.push_back(std::pow(cube.geometry.radius[i], 3) * 4.1887902047863905);
    cube.velocity.push_back({std::sin(double(i)), 0, std::cos(double(i))});
  }
  for (std::size_t k = 0; k < cube.geometry.bonds.size(); ++k) {
    cube.bond_rest_length.push_back(1.0 + 1e-3 * double(k));
    cube.bond_broken.push_back(k % 7 == 0);
  }
  write_checkpoint(cube, dir / "cube.h5");
  expect_same(read_checkpoint(dir / "cube.h5"), cube);
}

TEST(Checkpoint, PositionsAtRebuildRoundTripSortedWithTheIds) {
  const auto dir = basalt::test::scratch_dir("ckpt-rebuild");
  Checkpoint c = sample_checkpoint();
  for (std::size_t i = 0; i < c.size(); ++i)
    c.position_at_rebuild.push_back({0.1 * double(c.geometry.id[i]) + 1e-17, 0, -1.0 / 3});
  c.rebuild_step = 1650;
  c.rebuild_pending = true;
  write_checkpoint(c, dir / "ckpt_1700.h5");
  const Checkpoint back = read_checkpoint(dir / "ckpt_1700.h5");
  ASSERT_EQ(back.position_at_rebuild.size(), back.size());
  for (std::size_t i = 0; i < back.size(); ++i)
    EXPECT_EQ(back.position_at_rebuild[i][0], 0.1 * double(back.geometry.id[i]) + 1e-17);
  EXPECT_EQ(back.rebuild_step, 1650);
  EXPECT_TRUE(back.rebuild_pending);
  EXPECT_TRUE(back.geometry.attributes.count("rebuild_step") == 0);  // not taken for provenance
  // Without them (an older checkpoint): empty, step -1.
  const Checkpoint plain = read_checkpoint([&] {
    write_checkpoint(sample_checkpoint(), dir / "plain.h5");
    return dir / "plain.h5";
  }());
  EXPECT_TRUE(plain.position_at_rebuild.empty());
  EXPECT_EQ(plain.rebuild_step, -1);
  // A rebuild after the checkpoint's own step is refused, naming the attribute.
  c.rebuild_step = 1701;
  expect_format_error([&] { write_checkpoint(c, dir / "bad.h5"); }, {"rebuild_step", "1701"});
  // The dataset without its attribute is refused on reading.
  c.rebuild_step = 1650;
  write_checkpoint(c, dir / "noattr.h5");
  edit_file(dir / "noattr.h5", [](hid_t f) { H5Adelete(f, "rebuild_step"); });
  expect_format_error([&] { read_checkpoint(dir / "noattr.h5"); }, {"noattr.h5", "rebuild_step", "missing"});
}

namespace {

// Overwrites value `k` (counted over all rows and columns) of an existing float64 dataset.
void poke(hid_t f, const char* path, hsize_t k, double value) {
  const hid_t ds = H5Dopen2(f, path, H5P_DEFAULT);
  ASSERT_GE(ds, 0) << path;
  const hid_t space = H5Dget_space(ds);
  std::vector<double> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
  ASSERT_GE(H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0);
  v.at(k) = value;
  ASSERT_GE(H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0);
  H5Sclose(space);
  H5Dclose(ds);
}

}  // namespace

// Issue 16 (fuzzing the checkpoint reader): the inverse masses, the positions at the last rebuild and a
// servo wall's motion state were read without a check, so a damaged checkpoint restarted with NaN
// inverse masses (NaN accelerations from the first step) or positions that no rank owns. Each is now
// refused on reading, naming the file, the dataset and the particle, and never written.
TEST(Checkpoint, NonFiniteRestartStateIsRefused) {
  const auto dir = basalt::test::scratch_dir("ckpt-nonfinite");
  const auto file = dir / "ckpt_1700.h5";
  Checkpoint c = sample_checkpoint();
  for (std::size_t i = 0; i < c.size(); ++i) {
    c.inv_mass.push_back(1.0 / c.geometry.mass[i]);
    c.position_at_rebuild.push_back(c.geometry.position[i]);
  }
  c.rebuild_step = 1650;
  auto damaged = [&](const char* path, hsize_t k, double value) {
    write_checkpoint(c, file);
    edit_file(file, [&](hid_t f) { poke(f, path, k, value); });
  };
  // Stored sorted by id (3, 5, 8, 17, 40, 99): value 1 is id 5's, row 2 of an (N, 3) dataset is id 8's.
  damaged("/particles/inverse_mass", 1, std::nan(""));
  expect_format_error([&] { read_checkpoint(file); }, {"ckpt_1700.h5: /particles/inverse_mass: particle id "
                                                       "5: inverse mass must be finite and >= 0, got nan"});
  damaged("/particles/inverse_mass", 0, -0.5);
  expect_format_error([&] { read_checkpoint(file); }, {"/particles/inverse_mass: particle id 3", "got -0.5"});
  damaged("/particles/inverse_mass", 5, HUGE_VAL);
  expect_format_error([&] { read_checkpoint(file); }, {"/particles/inverse_mass: particle id 99", "got inf"});
  damaged("/particles/position_at_rebuild", 7, -HUGE_VAL);
  expect_format_error([&] { read_checkpoint(file); },
                      {"ckpt_1700.h5: /particles/position_at_rebuild: particle id 8: position at the last "
                       "rebuild is not finite"});
  damaged("/particles/position_at_rebuild", 17, std::nan(""));
  expect_format_error([&] { read_checkpoint(file); }, {"/particles/position_at_rebuild: particle id 99"});
  damaged("/walls/top/motion_state", 2, std::nan(""));
  expect_format_error([&] { read_checkpoint(file); },
                      {"ckpt_1700.h5: /walls/top/motion_state: a value is not finite"});
  damaged("/walls/top/motion_state", 0, HUGE_VAL);
  expect_format_error([&] { read_checkpoint(file); }, {"/walls/top/motion_state"});
  // Zero inverse masses stay valid (a float run may round 1/m of a huge mass to 0).
  c.inv_mass[2] = 0.0;
  write_checkpoint(c, file);
  EXPECT_EQ(read_checkpoint(file).inv_mass.size(), c.size());
  // Nor can such a state be written.
  c.inv_mass[2] = std::nan("");
  expect_format_error([&] { write_checkpoint(c, dir / "bad.h5"); }, {"bad.h5: /particles/inverse_mass"});
  c.inv_mass[2] = 1.0;
  c.walls[0].motion_state[1] = -HUGE_VAL;
  expect_format_error([&] { write_checkpoint(c, dir / "bad.h5"); }, {"bad.h5: /walls/top/motion_state"});
  EXPECT_FALSE(fs::exists(dir / "bad.h5"));
}

TEST(Checkpoint, CompletionMarkIsRequired) {
  const auto dir = basalt::test::scratch_dir("ckpt-complete");
  const auto file = dir / "ckpt_5.h5";
  write_checkpoint(sample_checkpoint(), file);
  edit_file(file, [](hid_t f) { H5Adelete(f, "complete"); });
  expect_format_error([&] { read_checkpoint(file); },
                      {file.string(), "attribute 'complete' of /", "not completely written"});
  EXPECT_FALSE(is_complete_checkpoint(file));
  edit_file(file, [](hid_t f) { set_int_attribute(f, "complete", 0); });
  expect_format_error([&] { read_checkpoint(file); }, {file.string(), "attribute 'complete' of /: is 0"});
  EXPECT_FALSE(is_complete_checkpoint(file));
}

TEST(Checkpoint, OtherSchemaOrNewerVersionIsRefused) {
  const auto dir = basalt::test::scratch_dir("ckpt-schema");
  write_h5(basalt::io::test::sample_geometry(), dir / "geometry.h5");
  expect_format_error(
      [&] { read_checkpoint(dir / "geometry.h5"); },
      {"geometry.h5", "attribute 'schema' of /: is 'basalt-geometry', expected 'basalt-checkpoint'"});
  EXPECT_FALSE(is_complete_checkpoint(dir / "geometry.h5"));

  write_checkpoint(sample_checkpoint(), dir / "ckpt_1.h5");
  expect_format_error([&] { read_h5(dir / "ckpt_1.h5"); },
                      {"ckpt_1.h5", "is 'basalt-checkpoint', expected 'basalt-geometry'", "read_checkpoint"});
  edit_file(dir / "ckpt_1.h5", [](hid_t f) { set_int_attribute(f, "schema_version", 2); });
  expect_format_error(
      [&] { read_checkpoint(dir / "ckpt_1.h5"); },
      {"ckpt_1.h5", "attribute 'schema_version' of /", "basalt-checkpoint version 2 is newer"});
  EXPECT_FALSE(is_complete_checkpoint(dir / "ckpt_1.h5"));
}

TEST(Checkpoint, InconsistentContentsNameTheDataset) {
  const auto dir = basalt::test::scratch_dir("ckpt-contents");
  const auto file = dir / "ckpt_9.h5";
  write_checkpoint(sample_checkpoint(), file);
  edit_file(file, [](hid_t f) {
    H5Ldelete(f, "/bonds/rest_length", H5P_DEFAULT);
    const hsize_t dims[1] = {3};
    const double v[3] = {1, 1, 1};
    const hid_t space = H5Screate_simple(1, dims, nullptr);
    const hid_t ds =
        H5Dcreate2(f, "/bonds/rest_length", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v);
    H5Dclose(ds);
    H5Sclose(space);
  });
  expect_format_error([&] { read_checkpoint(file); },
                      {"ckpt_9.h5: /bonds/rest_length: 3 values for 4 bonds"});
  EXPECT_FALSE(is_complete_checkpoint(file));

  write_checkpoint(sample_checkpoint(), file);
  edit_file(file, [](hid_t f) { H5Ldelete(f, "/particles/velocity", H5P_DEFAULT); });
  expect_format_error([&] { read_checkpoint(file); }, {"ckpt_9.h5: /particles/velocity: missing dataset"});

  write_checkpoint(sample_checkpoint(), file);
  edit_file(file, [](hid_t f) { H5Ldelete(f, "/walls/top/normal", H5P_DEFAULT); });
  expect_format_error([&] { read_checkpoint(file); }, {"ckpt_9.h5: /walls/top/normal: missing dataset"});
}

TEST(Checkpoint, InvalidStateIsNotWrittenAndKeepsThePreviousFile) {
  const auto dir = basalt::test::scratch_dir("ckpt-invalid");
  const auto file = dir / "ckpt_2.h5";
  write_checkpoint(sample_checkpoint(), file);
  const auto before = read_bytes(file);

  Checkpoint c = sample_checkpoint();
  c.velocity.pop_back();
  expect_format_error([&] { write_checkpoint(c, file); },
                      {"ckpt_2.h5: /particles/velocity: 5 velocities for 6"});
  c = sample_checkpoint();
  c.geometry.mass.clear();
  expect_format_error([&] { write_checkpoint(c, file); }, {"ckpt_2.h5: /particles/mass", "0 masses for 6"});
  c = sample_checkpoint();
  c.bond_broken.pop_back();
  expect_format_error([&] { write_checkpoint(c, file); }, {"ckpt_2.h5: /bonds/broken: 3 values for 4 bonds"});
  c = sample_checkpoint();
  c.walls[1].name = "top";
  expect_format_error([&] { write_checkpoint(c, file); },
                      {"ckpt_2.h5: /walls/top: two walls have this name"});
  c = sample_checkpoint();
  c.velocity[2][1] = NAN;
  expect_format_error([&] { write_checkpoint(c, file); },
                      {"/particles/velocity: particle id 17: velocity is not finite"});
  c = sample_checkpoint();
  c.geometry.attributes["step"] = "clash";  // provenance may not shadow a run attribute
  expect_format_error([&] { write_checkpoint(c, file); }, {"attribute 'step' of /", "reserves"});

  EXPECT_TRUE(read_bytes(file) == before);
  EXPECT_FALSE(fs::exists(dir / "ckpt_2.h5.partial"));
}

TEST(Checkpoint, LatestSkipsTruncatedPartialAndIncompleteFiles) {
  const auto dir = basalt::test::scratch_dir("ckpt-latest");
  EXPECT_EQ(latest_complete_checkpoint(dir), fs::path());
  EXPECT_EQ(latest_complete_checkpoint(dir / "no-such-folder"), fs::path());

  Checkpoint c = sample_checkpoint();
  for (std::int64_t step : {100, 200}) {
    c.step = step;
    write_checkpoint(c, dir / fmt::format("ckpt_{}.h5", step));
  }
  EXPECT_EQ(latest_complete_checkpoint(dir), dir / "ckpt_200.h5");
  c.step = 900;
  write_checkpoint(c, dir / "ckpt_000900.h5");  // zero-padded steps count as numbers
  EXPECT_EQ(latest_complete_checkpoint(dir), dir / "ckpt_000900.h5");
  fs::remove(dir / "ckpt_000900.h5");

  // A crash while copying: the first half of a real checkpoint's bytes.
  const auto bytes = read_bytes(dir / "ckpt_200.h5");
  write_bytes(dir / "ckpt_300.h5", bytes.substr(0, bytes.size() / 2));
  expect_format_error([&] { read_checkpoint(dir / "ckpt_300.h5"); }, {"ckpt_300.h5", "file is truncated"});
  EXPECT_FALSE(is_complete_checkpoint(dir / "ckpt_300.h5"));
  // A writer that died before its rename; a file without the completion mark; unrelated names.
  write_bytes(dir / "ckpt_400.h5.partial", bytes);
  fs::copy_file(dir / "ckpt_200.h5", dir / "ckpt_500.h5");
  edit_file(dir / "ckpt_500.h5", [](hid_t f) { H5Adelete(f, "complete"); });
  write_bytes(dir / "ckpt_600.h5", "not hdf5");
  write_bytes(dir / "ckpt_-700.h5", bytes);
  write_bytes(dir / "ckpt_abc.h5", bytes);
  write_bytes(dir / "notes.txt", "x");
  fs::create_directories(dir / "ckpt_800.h5");

  EXPECT_EQ(latest_complete_checkpoint(dir), dir / "ckpt_200.h5");
  EXPECT_EQ(read_checkpoint(latest_complete_checkpoint(dir)).step, 200);
}

TEST(Checkpoint, UnwritableDestinationNamesThePath) {
  const auto dir = basalt::test::scratch_dir("ckpt-unwritable");
  write_bytes(dir / "a-file", "x");
  const auto target = dir / "a-file" / "ckpt_1.h5";  // parent is a regular file: even root cannot create it
  expect_format_error([&] { write_checkpoint(sample_checkpoint(), target); },
                      {target.string(), "cannot create", "is not a folder"});
  EXPECT_FALSE(fs::exists(dir / "a-file" / "ckpt_1.h5.partial"));
  EXPECT_EQ(read_bytes(dir / "a-file"), "x");
  const auto missing = dir / "missing" / "ckpt_1.h5";
  expect_format_error([&] { write_checkpoint(sample_checkpoint(), missing); },
                      {missing.string(), "cannot create: folder", "does not exist"});
}

TEST(Checkpoint, EmptyStateRoundTrips) {
  const auto dir = basalt::test::scratch_dir("ckpt-empty");
  Checkpoint c;  // no particles, bonds or walls: e.g. a rank-less test scene at step 0
  c.scene_text = "";
  write_checkpoint(c, dir / "ckpt_0.h5");
  EXPECT_TRUE(is_complete_checkpoint(dir / "ckpt_0.h5"));
  expect_same(read_checkpoint(dir / "ckpt_0.h5"), c);
  EXPECT_EQ(latest_complete_checkpoint(dir), dir / "ckpt_0.h5");
}

TEST(Checkpoint, ParticleFieldsAndContactHistoryRoundTripSortedWithTheIds) {
  const auto dir = basalt::test::scratch_dir("ckpt-fields");
  Checkpoint c = sample_checkpoint();
  std::vector<double> broken;
  for (std::size_t i = 0; i < c.size(); ++i) broken.push_back(double(c.geometry.id[i] % 4));
  c.particle_fields.emplace_back("bonds_broken", broken);
  const auto a = c.geometry.id.front(), b = c.geometry.id.back();
  c.contact_ids = {{b, a}, {a, b}};
  c.contact_model = {0, 1};
  c.contact_width = 2;
  c.contact_history = {1.5, -2.0, 3.0, 0.25};
  write_checkpoint(c, dir / "ckpt_1700.h5");
  const Checkpoint back = read_checkpoint(dir / "ckpt_1700.h5");
  ASSERT_EQ(back.particle_fields.size(), 1u);
  EXPECT_EQ(back.particle_fields[0].first, "bonds_broken");
  for (std::size_t i = 0; i < back.size(); ++i)  // the values followed their ids through the sort
    EXPECT_EQ(back.particle_fields[0].second[i], double(back.geometry.id[i] % 4));
  EXPECT_EQ(back.contact_ids, c.contact_ids);
  EXPECT_EQ(back.contact_model, c.contact_model);
  EXPECT_EQ(back.contact_width, 2u);
  EXPECT_EQ(back.contact_history, c.contact_history);
  // Bad ones are refused, naming the dataset: a field of the wrong length, one that takes a fixed
  // dataset's name, a contact naming no particle, a non-finite history value.
  Checkpoint bad = c;
  bad.particle_fields[0].second.pop_back();
  expect_format_error([&] { write_checkpoint(bad, dir / "bad.h5"); }, {"/particles/bonds_broken", "values"});
  bad = c;
  bad.particle_fields[0].first = "velocity";
  expect_format_error([&] { write_checkpoint(bad, dir / "bad.h5"); }, {"/particles/velocity"});
  bad = c;
  bad.contact_ids[1][1] = 999999;
  expect_format_error([&] { write_checkpoint(bad, dir / "bad.h5"); }, {"/contacts/ids", "999999"});
  bad = c;
  bad.contact_history[3] = std::nan("");
  expect_format_error([&] { write_checkpoint(bad, dir / "bad.h5"); }, {"/contacts/history"});
}

TEST(Checkpoint, BreakPositionsRoundTripOnePerBrokenBond) {
  // /bonds/break_position: where each broken bond broke, one row per bond whose flag is not 0, in bond
  // order; a row of NaN is "not known". Written only when known: a run without breaks has no dataset.
  const auto dir = basalt::test::scratch_dir("ckpt-break-position");
  Checkpoint c = sample_checkpoint();
  c.bond_broken = {0, 1 | (1 << 2), 0, 2 | (3 << 2)};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.bond_break_position = {{1.5, 2.25, -3.0000000000000004}, {nan, nan, nan}};
  write_checkpoint(c, dir / "ckpt_1.h5");
  const Checkpoint back = read_checkpoint(dir / "ckpt_1.h5");
  EXPECT_EQ(back.bond_broken, c.bond_broken);
  ASSERT_EQ(back.bond_break_position.size(), 2u);
  EXPECT_EQ(back.bond_break_position[0], c.bond_break_position[0]);
  EXPECT_TRUE(std::isnan(back.bond_break_position[1][0]) && std::isnan(back.bond_break_position[1][2]));

  write_checkpoint(sample_checkpoint(), dir / "ckpt_2.h5");
  EXPECT_TRUE(read_checkpoint(dir / "ckpt_2.h5").bond_break_position.empty());

  Checkpoint bad = c;
  bad.bond_break_position.pop_back();
  expect_format_error([&] { write_checkpoint(bad, dir / "ckpt_3.h5"); },
                      {"ckpt_3.h5: /bonds/break_position: 1 rows for 2 broken bonds"});
  bad = c;
  bad.bond_break_position[1][0] = 4.0;  // partly NaN: neither a position nor "not known"
  expect_format_error([&] { write_checkpoint(bad, dir / "ckpt_3.h5"); },
                      {"/bonds/break_position: row 1: a position must be finite"});
  EXPECT_FALSE(fs::exists(dir / "ckpt_3.h5"));
}
