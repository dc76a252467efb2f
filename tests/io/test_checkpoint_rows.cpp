// Checkpoints read in row ranges (CheckpointFile, basalt/io/checkpoint_rows.hpp), as basalt-run's sliced
// restart reads them: any split of the particle, bond, break-position and contact rows gives back exactly
// the rows read_checkpoint reads, empty ranges included; a damaged row is refused with read_checkpoint's
// message by the range holding it (and only by it); a damaged shape is refused on opening.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <functional>
#include <string>

#include "basalt/io/checkpoint.hpp"
#include "basalt/io/checkpoint_rows.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace basalt::io;
using basalt::io::test::expect_format_error;

namespace {

// The sample geometry (ids 3, 5, 8, 17, 40, 99 once sorted) with every optional dataset: inverse masses,
// positions at the last rebuild, a particle field, two broken bonds of four with break positions (one not
// known), three contacts (one with a wall) of width 2.
Checkpoint full_checkpoint() {
  Checkpoint c;
  c.geometry = basalt::io::test::sample_geometry();
  c.geometry.sort_by_id();
  const std::size_t n = c.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double s = double(i + 1);
    c.velocity.push_back({0.1 * s, -0.2 * s, 0.3 / s});
    c.inv_mass.push_back(1.0 / c.geometry.mass[i]);
    c.position_at_rebuild.push_back(
        {c.geometry.position[i][0] + 1e-3 * s, c.geometry.position[i][1], c.geometry.position[i][2]});
  }
  c.particle_fields = {{"broken_bonds", {0, 1, 2, 0, 1, 0}}, {"angular_velocity_x", {1, 2, 3, 4, 5, 6}}};
  c.bond_rest_length = {0.75, 1.5, 0.5, 1.0};
  c.bond_broken = {0, 1 + 4, 0, 2};
  c.bond_break_position = {{1.0, 2.0, 3.0}, {std::nan(""), std::nan(""), std::nan("")}};
  c.rebuild_step = 1650;
  c.rebuild_pending = true;
  c.walls = {{"top", {0, 0, 15}, {0, 0, -1}, {0, 0, 0}, {0, 0, 12.5}, {}}};
  c.contact_ids = {{3, 8}, {17, -1}, {40, 99}};
  c.contact_model = {0, 1, 0};
  c.contact_width = 2;
  c.contact_history = {0.5, -0.25, 1e-9, 2.0, 3.0, 4.0};
  c.step = 1700;
  c.time = 1.7;
  c.dt = 1e-3;
  c.scene_text = "[run]\ndt = 1e-3\n";
  return c;
}

void edit_file(const fs::path& file, const std::function<void(hid_t)>& edit) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  edit(f);
  ASSERT_GE(H5Fclose(f), 0);
}

void poke(hid_t f, const char* path, std::size_t k, double value) {
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

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const FormatError& e) {
    return e.what();
  }
  return "(no error)";
}

// NaN-aware equality of 3-vectors.
bool same(const Vec3& a, const Vec3& b) {
  for (int d = 0; d < 3; ++d)
    if (!(a[d] == b[d] || (std::isnan(a[d]) && std::isnan(b[d])))) return false;
  return true;
}

}  // namespace

TEST(CheckpointRows, HeaderDescribesTheFile) {
  const auto file = basalt::test::scratch_dir("ckpt-rows-header") / "ckpt_1700.h5";
  const Checkpoint c = full_checkpoint();
  write_checkpoint(c, file);
  const CheckpointFile f(file);
  const auto& h = f.header();
  EXPECT_EQ(h.particles, 6u);
  EXPECT_EQ(h.bonds, 4u);
  EXPECT_TRUE(h.has_break_position);
  EXPECT_EQ(h.break_positions, 2u);
  EXPECT_EQ(h.contacts, 3u);
  EXPECT_TRUE(h.has_inverse_mass);
  EXPECT_TRUE(h.has_position_at_rebuild);
  EXPECT_EQ(h.particle_fields,
            (std::vector<std::string>{"angular_velocity_x", "broken_bonds"}));  // HDF5 order
  EXPECT_EQ(h.run.rebuild_step, 1650);
  EXPECT_TRUE(h.run.rebuild_pending);
  EXPECT_EQ(h.run.contact_width, 2u);
  EXPECT_EQ(h.run.step, 1700);
  EXPECT_EQ(h.run.time, 1.7);
  EXPECT_EQ(h.run.dt, 1e-3);
  EXPECT_EQ(h.run.scene_text, c.scene_text);
  ASSERT_EQ(h.run.walls.size(), 1u);
  EXPECT_EQ(h.run.walls[0].force, c.walls[0].force);
  EXPECT_EQ(h.run.geometry.attributes, c.geometry.attributes);
  EXPECT_EQ(h.run.geometry.box_max, c.geometry.box_max);
  EXPECT_EQ(h.run.size(), 0u);  // no rows
  // header_of gives the same description of a checkpoint held whole.
  const auto w = header_of(read_checkpoint(file));
  EXPECT_EQ(w.particles, h.particles);
  EXPECT_EQ(w.bonds, h.bonds);
  EXPECT_EQ(w.break_positions, h.break_positions);
  EXPECT_EQ(w.contacts, h.contacts);
  EXPECT_EQ(w.particle_fields, h.particle_fields);
  EXPECT_EQ(w.run.scene_text, h.run.scene_text);
  EXPECT_EQ(w.run.geometry.attributes, h.run.geometry.attributes);
}

TEST(CheckpointRows, EverySplitGivesTheWholeFilesRows) {
  const auto file = basalt::test::scratch_dir("ckpt-rows-split") / "ckpt_1700.h5";
  write_checkpoint(full_checkpoint(), file);
  const Checkpoint whole = read_checkpoint(file);
  const CheckpointFile f(file);
  // Every range [b, e), empty ones included: each row equals the whole file's.
  for (std::size_t b = 0; b <= whole.size(); ++b)
    for (std::size_t e = b; e <= whole.size(); ++e) {
      Checkpoint part;
      f.read_particles(b, e, part);
      ASSERT_EQ(part.size(), e - b);
      for (std::size_t i = b; i < e; ++i) {
        const std::size_t j = i - b;
        EXPECT_EQ(part.geometry.id[j], whole.geometry.id[i]);
        EXPECT_EQ(part.geometry.position[j], whole.geometry.position[i]);
        EXPECT_EQ(part.geometry.radius[j], whole.geometry.radius[i]);
        EXPECT_EQ(part.geometry.tag[j], whole.geometry.tag[i]);
        EXPECT_EQ(part.geometry.mass[j], whole.geometry.mass[i]);
        EXPECT_EQ(part.velocity[j], whole.velocity[i]);
        EXPECT_EQ(part.inv_mass[j], whole.inv_mass[i]);
        EXPECT_EQ(part.position_at_rebuild[j], whole.position_at_rebuild[i]);
        ASSERT_EQ(part.particle_fields.size(), whole.particle_fields.size());
        for (std::size_t k = 0; k < part.particle_fields.size(); ++k) {
          EXPECT_EQ(part.particle_fields[k].first, whole.particle_fields[k].first);
          EXPECT_EQ(part.particle_fields[k].second[j], whole.particle_fields[k].second[i]);
        }
      }
    }
  // Bonds split anywhere, with the break positions of the broken ones among them: the rows before a range
  // count its broken bonds' first break row.
  for (std::size_t b = 0; b <= whole.geometry.bonds.size(); ++b)
    for (std::size_t e = b; e <= whole.geometry.bonds.size(); ++e) {
      Checkpoint part;
      f.read_bonds(b, e, part);
      ASSERT_EQ(part.geometry.bonds.size(), e - b);
      std::size_t before = 0, broken = 0;
      for (std::size_t k = 0; k < b; ++k) before += whole.bond_broken[k] != 0;
      for (std::size_t k = b; k < e; ++k) {
        EXPECT_EQ(part.geometry.bonds[k - b].a, whole.geometry.bonds[k].a);
        EXPECT_EQ(part.geometry.bonds[k - b].b, whole.geometry.bonds[k].b);
        EXPECT_EQ(part.geometry.bonds[k - b].tag, whole.geometry.bonds[k].tag);
        EXPECT_EQ(part.bond_rest_length[k - b], whole.bond_rest_length[k]);
        EXPECT_EQ(part.bond_broken[k - b], whole.bond_broken[k]);
        broken += whole.bond_broken[k] != 0;
      }
      f.read_break_positions(before, before + broken, part);
      ASSERT_EQ(part.bond_break_position.size(), broken);
      for (std::size_t k = 0; k < broken; ++k)
        EXPECT_TRUE(same(part.bond_break_position[k], whole.bond_break_position[before + k]));
    }
  // Contacts split anywhere (the one with a wall, -1, included).
  for (std::size_t b = 0; b <= whole.contact_ids.size(); ++b)
    for (std::size_t e = b; e <= whole.contact_ids.size(); ++e) {
      Checkpoint part;
      f.read_contacts(b, e, part);
      ASSERT_EQ(part.contact_ids.size(), e - b);
      EXPECT_EQ(part.contact_width, 2u);
      for (std::size_t k = b; k < e; ++k) {
        EXPECT_EQ(part.contact_ids[k - b], whole.contact_ids[k]);
        EXPECT_EQ(part.contact_model[k - b], whole.contact_model[k]);
        EXPECT_EQ(part.contact_history[2 * (k - b)], whole.contact_history[2 * k]);
        EXPECT_EQ(part.contact_history[2 * (k - b) + 1], whole.contact_history[2 * k + 1]);
      }
    }
  // Ranges beyond the rows are refused, naming them.
  Checkpoint part;
  expect_format_error([&] { f.read_particles(2, 7, part); },
                      {"/particles", "rows 2 to 7 asked of 6 particles"});
  expect_format_error([&] { f.read_bonds(3, 2, part); }, {"/bonds", "rows 3 to 2 asked of 4 bonds"});
  expect_format_error([&] { f.read_contacts(0, 4, part); }, {"/contacts", "asked of 3 contacts"});
  expect_format_error([&] { f.read_break_positions(1, 3, part); }, {"/bonds/break_position", "asked of 2"});
}

// A damaged row: the range holding it is refused with read_checkpoint's very message; the others read.
TEST(CheckpointRows, DamagedRowsAreRefusedByTheirRange) {
  const auto dir = basalt::test::scratch_dir("ckpt-rows-damaged");
  const auto file = dir / "ckpt_1700.h5";
  struct Case {
    const char* dataset;
    std::size_t value;  // index of the value poked in the flat dataset
    double poked;
    std::size_t row;  // the row holding it (particle, bond, break position or contact)
  };
  const Case cases[] = {
      {"/particles/velocity", 3 * 4 + 1, std::nan(""), 4},
      {"/particles/inverse_mass", 2, -0.5, 2},
      {"/particles/position_at_rebuild", 3 * 5 + 2, HUGE_VAL, 5},
      {"/particles/broken_bonds", 1, std::nan(""), 1},
      {"/particles/position", 3 * 3, std::nan(""), 3},
      {"/particles/radius", 0, -1.0, 0},
      {"/bonds/rest_length", 2, -1.0, 2},
      {"/bonds/break_position", 3 * 1 + 1, 5.0, 1},  // NaN in two of three: neither known nor finite
      {"/contacts/history", 2 * 2 + 1, HUGE_VAL, 2},
  };
  for (const auto& k : cases) {
    SCOPED_TRACE(k.dataset);
    write_checkpoint(full_checkpoint(), file);
    edit_file(file, [&](hid_t f) { poke(f, k.dataset, k.value, k.poked); });
    const std::string expected = message_of([&] { (void)read_checkpoint(file); });
    ASSERT_NE(expected, "(no error)");
    const CheckpointFile f(file);
    const std::string ds = k.dataset;
    const auto read = [&](std::size_t b, std::size_t e) {
      Checkpoint part;
      if (ds.rfind("/particles/", 0) == 0) f.read_particles(b, e, part);
      if (ds == "/bonds/rest_length") f.read_bonds(b, e, part);
      if (ds == "/bonds/break_position") f.read_break_positions(b, e, part);
      if (ds == "/contacts/history") f.read_contacts(b, e, part);
    };
    EXPECT_EQ(message_of([&] { read(k.row, k.row + 1); }), expected);
    EXPECT_EQ(message_of([&] { read(0, k.row + 1); }), expected);
    EXPECT_EQ(message_of([&] { read(0, k.row); }), "(no error)");
    EXPECT_EQ(message_of([&] { read(k.row + 1, k.row + 1); }), "(no error)");  // empty
  }
}

// Damaged shapes and marks are refused on opening, with read_checkpoint's message.
TEST(CheckpointRows, DamagedFilesAreRefusedOnOpening) {
  const auto dir = basalt::test::scratch_dir("ckpt-rows-shape");
  const auto file = dir / "ckpt_1700.h5";
  const std::function<void(hid_t)> edits[] = {
      [](hid_t f) { H5Adelete(f, "complete"); },
      [](hid_t f) { H5Ldelete(f, "/particles/velocity", H5P_DEFAULT); },
      [](hid_t f) { H5Ldelete(f, "/particles/mass", H5P_DEFAULT); },
      [](hid_t f) { H5Ldelete(f, "/bonds/broken", H5P_DEFAULT); },
      [](hid_t f) { H5Ldelete(f, "/contacts/model", H5P_DEFAULT); },
      [](hid_t f) { H5Adelete(f, "rebuild_step"); },
      [](hid_t f) { H5Ldelete(f, "/walls/top/normal", H5P_DEFAULT); },
      [](hid_t f) { poke(f, "/walls/top/force", 1, std::nan("")); },
  };
  for (const auto& edit : edits) {
    write_checkpoint(full_checkpoint(), file);
    edit_file(file, edit);
    const std::string expected = message_of([&] { (void)read_checkpoint(file); });
    ASSERT_NE(expected, "(no error)");
    EXPECT_EQ(message_of([&] { CheckpointFile f(file); }), expected);
  }
  expect_format_error([&] { CheckpointFile f(dir / "missing.h5"); }, {"missing.h5"});
}
