// Malformed basalt-geometry HDF5 files, made with the HDF5 C API from a valid one: every error
// names the file, the dataset or attribute, and what is wrong; HDF5 prints nothing itself.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "basalt/io/geometry_rows.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace basalt::io;
using basalt::io::test::expect_format_error;

namespace {

// Ten particles with ids 0, 10, 20, ... and three bonds.
Geometry ten_particles() {
  Geometry g;
  for (int i = 0; i < 10; ++i) g.add_particle(10 * i, {1.0 * i, 0, 0}, 0.5, i % 3);
  g.add_bond(0, 10);
  g.add_bond(10, 20, 1);
  g.add_bond(50, 60);
  g.box_max = {10, 1, 1};
  return g;
}

void check(herr_t status, const char* what) { ASSERT_GE(status, 0) << what; }

// Opens a valid file read-write and lets `edit` damage it.
void edit_file(const fs::path& file, const std::function<void(hid_t)>& edit) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  edit(f);
  check(H5Fclose(f), "close");
}

// Replaces dataset `path` by one of `rows` x `columns` values of type `type`.
void replace_dataset(hid_t f, const std::string& path, hid_t type, const void* data, hsize_t rows,
                     hsize_t columns = 0) {
  if (H5Lexists(f, path.c_str(), H5P_DEFAULT) > 0) check(H5Ldelete(f, path.c_str(), H5P_DEFAULT), "delete");
  const hsize_t dims[2] = {rows, columns};
  const hid_t space = H5Screate_simple(columns ? 2 : 1, dims, nullptr);
  const hid_t ds = H5Dcreate2(f, path.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(ds, 0) << path;
  check(H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "write");
  H5Dclose(ds);
  H5Sclose(space);
}

template <class T>
void replace(hid_t f, const std::string& path, const std::vector<T>& v, hsize_t columns = 0) {
  hid_t type = std::is_same_v<T, double>         ? H5T_NATIVE_DOUBLE
               : std::is_same_v<T, std::int32_t> ? H5T_NATIVE_INT32
                                                 : H5T_NATIVE_INT64;
  replace_dataset(f, path, type, v.data(), columns ? v.size() / columns : v.size(), columns);
}

void set_string_attribute(hid_t f, const char* name, const char* value) {
  if (H5Aexists(f, name) > 0) check(H5Adelete(f, name), "delete attribute");
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t a = H5Acreate2(f, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  check(H5Awrite(a, type, &value), "write attribute");
  H5Aclose(a);
  H5Sclose(space);
  H5Tclose(type);
}

void set_int_attribute(hid_t f, const char* name, std::int32_t value) {
  if (H5Aexists(f, name) > 0) check(H5Adelete(f, name), "delete attribute");
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t a = H5Acreate2(f, name, H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT);
  check(H5Awrite(a, H5T_NATIVE_INT32, &value), "write attribute");
  H5Aclose(a);
  H5Sclose(space);
}

class H5BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = basalt::test::scratch_dir("h5-bad");
    file_ = dir_ / "cube.h5";
    write_h5(ten_particles(), file_);
  }
  void expect_error(std::initializer_list<std::string> fragments) {
    expect_format_error([&] { read_h5(file_); }, fragments);
  }
  std::vector<double> radii(double value_at_3) {
    std::vector<double> r(10, 0.5);
    r[3] = value_at_3;
    return r;
  }

  fs::path dir_;
  fs::path file_;
};

}  // namespace

TEST_F(H5BadInput, TheUnmodifiedFileIsValid) {
  const auto g = read_h5(file_);
  EXPECT_EQ(g.size(), 10u);
  EXPECT_EQ(g.bonds.size(), 3u);
}

TEST_F(H5BadInput, TruncatedFile) {
  const auto bytes = basalt::io::test::read_bytes(file_);
  basalt::io::test::write_bytes(file_, bytes.substr(0, bytes.size() / 2));
  expect_error({"cube.h5", "file is truncated"});
  basalt::io::test::write_bytes(file_, bytes.substr(0, 6));
  expect_error({"cube.h5", "not an HDF5 file"});
  basalt::io::test::write_bytes(file_, "LSMGeometry 1.2\n");
  expect_error({"cube.h5", "not an HDF5 file"});
}

TEST_F(H5BadInput, TooFewOrTooManyValues) {
  edit_file(file_, [](hid_t f) { replace(f, "/particles/radius", std::vector<double>(9, 0.5)); });
  expect_error({"cube.h5: /particles/radius: 9 values for 10 particles"});
  edit_file(file_, [](hid_t f) { replace(f, "/particles/radius", std::vector<double>(10, 0.5)); });
  edit_file(file_, [](hid_t f) { replace(f, "/particles/position", std::vector<double>(33, 1.0), 3); });
  expect_error({"cube.h5: /particles/position: 11 rows for 10 particles"});
}

TEST_F(H5BadInput, MismatchedLengthsAndShapes) {
  edit_file(file_, [](hid_t f) { replace(f, "/bonds/tag", std::vector<std::int32_t>{0, 1}); });
  expect_error({"cube.h5: /bonds/tag: 2 values for 3 bonds"});
  edit_file(file_, [](hid_t f) { replace(f, "/particles/position", std::vector<double>(20, 1.0), 2); });
  expect_error({"cube.h5: /particles/position: expected shape (N, 3), found (10, 2)"});
  write_h5(ten_particles(), file_);
  edit_file(file_, [](hid_t f) { replace(f, "/particles/mass", std::vector<double>(11, 1.0)); });
  expect_error({"cube.h5: /particles/mass: 11 values for 10 particles"});
}

TEST_F(H5BadInput, NonNumericField) {
  edit_file(file_, [](hid_t f) {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, 4);
    const std::string text(40, 'x');
    replace_dataset(f, "/particles/radius", type, text.data(), 10);
    H5Tclose(type);
  });
  expect_error({"cube.h5: /particles/radius: expected floating-point values, found string values"});
}

TEST_F(H5BadInput, ValueOutOfRangeForItsType) {
  edit_file(file_, [](hid_t f) {
    std::vector<std::int64_t> tags(10, 1);
    tags[4] = std::int64_t{1} << 40;
    replace(f, "/particles/tag", tags);
  });
  expect_error({"cube.h5: /particles/tag", "out of range"});
}

TEST_F(H5BadInput, BondToMissingId) {
  edit_file(file_, [](hid_t f) {
    replace(f, "/bonds/pairs", std::vector<std::int64_t>{0, 10, 10, 25, 50, 60}, 2);
  });
  expect_error({"cube.h5: /bonds/pairs: bond 1 refers to particle id 25, which does not exist"});
  edit_file(file_, [](hid_t f) {
    replace(f, "/bonds/pairs", std::vector<std::int64_t>{0, 10, 20, 10, 50, 60}, 2);
  });
  expect_error({"cube.h5: /bonds/pairs: bond 1 is (20, 10)", "smaller id first"});
  edit_file(file_, [](hid_t f) {
    replace(f, "/bonds/pairs", std::vector<std::int64_t>{0, 10, 20, 20, 50, 60}, 2);
  });
  expect_error({"cube.h5: /bonds/pairs: bond 1 joins particle 20 to itself"});
}

// Issue 16: a pair bonded twice would act as two springs: refused by the reader and never written.
TEST_F(H5BadInput, DuplicateBondsAreRefused) {
  edit_file(file_, [](hid_t f) {
    replace(f, "/bonds/pairs", std::vector<std::int64_t>{0, 10, 10, 20, 0, 10}, 2);
  });
  expect_error({"cube.h5: /bonds/pairs: bonds 0 and 2", "both join particles 0 and 10", "two springs"});
  edit_file(file_, [](hid_t f) {
    replace(f, "/bonds/pairs", std::vector<std::int64_t>{0, 10, 50, 60, 50, 60}, 2);
  });
  expect_error({"cube.h5: /bonds/pairs: bonds 1 and 2", "both join particles 50 and 60"});
  Geometry g = ten_particles();
  g.add_bond(10, 0);  // the first bond in the other order
  expect_format_error([&] { write_h5(g, dir_ / "twice.h5"); },
                      {"twice.h5", "bonds 0 and 3", "both join particles 0 and 10"});
  EXPECT_FALSE(fs::exists(dir_ / "twice.h5"));
}

TEST_F(H5BadInput, NegativeOrZeroRadius) {
  edit_file(file_, [&](hid_t f) { replace(f, "/particles/radius", radii(-0.25)); });
  expect_error({"cube.h5: /particles/radius: particle id 30 (row 3)", "got -0.25"});
  edit_file(file_, [&](hid_t f) { replace(f, "/particles/radius", radii(0.0)); });
  expect_error({"cube.h5: /particles/radius: particle id 30 (row 3)", "> 0, got 0"});
}

TEST_F(H5BadInput, DuplicateOrUnsortedIds) {
  std::vector<std::int64_t> ids{0, 10, 20, 30, 40, 50, 60, 70, 80, 90};
  ids[5] = 40;
  edit_file(file_, [&](hid_t f) { replace(f, "/particles/id", ids); });
  expect_error({"cube.h5: /particles/id: duplicate id 40 (rows 4 and 5)"});
  ids[5] = 50;
  ids[6] = 5;
  edit_file(file_, [&](hid_t f) { replace(f, "/particles/id", ids); });
  expect_error({"cube.h5: /particles/id", "sorted ascending: id 5 at row 6 follows id 50"});
}

TEST_F(H5BadInput, WrongSchemaName) {
  edit_file(file_, [](hid_t f) { set_string_attribute(f, "schema", "lammps-data"); });
  expect_error({"cube.h5: attribute 'schema' of /: is 'lammps-data', expected 'basalt-geometry'"});
  edit_file(file_, [](hid_t f) { check(H5Adelete(f, "schema"), "delete"); });
  expect_error({"cube.h5: attribute 'schema' of /", "missing: not a Basalt file"});
}

TEST_F(H5BadInput, NewerSchemaVersion) {
  edit_file(file_, [](hid_t f) { set_int_attribute(f, "schema_version", 2); });
  expect_error({"cube.h5: attribute 'schema_version' of /", "version 2 is newer", "up to 1"});
  edit_file(file_, [](hid_t f) { set_int_attribute(f, "schema_version", 0); });
  expect_error({"cube.h5: attribute 'schema_version' of /: must be >= 1, found 0"});
}

TEST_F(H5BadInput, MissingDatasetGroupOrAttribute) {
  edit_file(file_, [](hid_t f) { check(H5Ldelete(f, "/particles/tag", H5P_DEFAULT), "delete"); });
  expect_error({"cube.h5: /particles/tag: missing dataset"});
  write_h5(ten_particles(), file_);
  edit_file(file_, [](hid_t f) { check(H5Ldelete(f, "/bonds", H5P_DEFAULT), "delete"); });
  expect_error({"cube.h5: /bonds: missing group"});
  write_h5(ten_particles(), file_);
  edit_file(file_, [](hid_t f) { check(H5Adelete(f, "box_min"), "delete"); });
  expect_error({"cube.h5: attribute 'box_min' of /: missing attribute"});
}

TEST_F(H5BadInput, BadRootAttributes) {
  edit_file(file_, [](hid_t f) { set_int_attribute(f, "length_unit", 3); });
  expect_error({"cube.h5: attribute 'length_unit' of /: expected a string, found integer values"});
  write_h5(ten_particles(), file_);
  edit_file(file_, [](hid_t f) { set_int_attribute(f, "my_note", 3); });
  expect_error({"cube.h5: attribute 'my_note' of /: provenance attributes must be strings"});
}

namespace {

// A dataset declared with `dims` (chunked by `chunk` rows when chunk > 0, with deflate when `deflate`),
// of which only the first `written` rows are written: HDF5 reads the rest as fill values.
void declare_dataset(hid_t f, const std::string& path, hid_t type, std::vector<hsize_t> dims, hsize_t chunk,
                     bool deflate, hsize_t written) {
  if (H5Lexists(f, path.c_str(), H5P_DEFAULT) > 0) check(H5Ldelete(f, path.c_str(), H5P_DEFAULT), "delete");
  const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  if (chunk > 0) {
    auto chunks = dims;
    chunks[0] = chunk;
    check(H5Pset_chunk(dcpl, static_cast<int>(dims.size()), chunks.data()), "chunk");
    if (deflate) check(H5Pset_deflate(dcpl, 6), "deflate");
  }
  const hid_t ds = H5Dcreate2(f, path.c_str(), type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  ASSERT_GE(ds, 0) << path;
  if (written > 0) {
    hsize_t width = 1;
    for (std::size_t k = 1; k < dims.size(); ++k) width *= dims[k];
    std::vector<double> values(written * width, 0.5);
    auto count = dims;
    count[0] = written;
    const std::vector<hsize_t> start(dims.size(), 0);
    const hid_t mem = H5Screate_simple(static_cast<int>(dims.size()), count.data(), nullptr);
    check(H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr), "select");
    check(H5Dwrite(ds, H5T_NATIVE_DOUBLE, mem, space, H5P_DEFAULT, values.data()), "write");
    H5Sclose(mem);
  }
  H5Dclose(ds);
  H5Pclose(dcpl);
  H5Sclose(space);
}

}  // namespace

// Issue 16 (fuzzing): a file of a few KB may declare 2^31 values it does not hold (HDF5 reads storage never
// written as fill values). The reader allocated them all (16 GiB here) before finding anything wrong;
// now it refuses any dataset whose declared bytes the file does not store, naming the file and dataset,
// before allocating, in read_h5 and in the sliced reader of basalt-run's start-up alike.
TEST_F(H5BadInput, DeclaredValuesMustBeInTheFile) {
  edit_file(file_, [](hid_t f) {
    declare_dataset(f, "/particles/id", H5T_STD_I64LE, {hsize_t{1} << 31}, 1024, false, 0);
  });
  expect_error(
      {"cube.h5: /particles/id: declares 2147483648 values (17179869184 bytes) but the file holds 0 "
       "bytes of them",
       "damaged or the dataset was never completely written"});
  expect_format_error([&] { GeometryFile f(file_); }, {"cube.h5: /particles/id: declares 2147483648 values"});

  write_h5(ten_particles(), file_);  // contiguous, never written
  edit_file(file_, [](hid_t f) {
    declare_dataset(f, "/particles/position", H5T_IEEE_F64LE, {hsize_t{1} << 30, 3}, 0, false, 0);
  });
  expect_error(
      {"cube.h5: /particles/position: declares 3221225472 values (25769803776 bytes) but the file "
       "holds 0 bytes"});

  write_h5(ten_particles(), file_);  // chunked, the first of three chunks written
  edit_file(file_,
            [](hid_t f) { declare_dataset(f, "/particles/radius", H5T_IEEE_F64LE, {10}, 4, false, 4); });
  expect_error({"cube.h5: /particles/radius: declares 10 values (80 bytes) but the file holds 32 bytes"});

  write_h5(ten_particles(), file_);  // compressed: one chunk of 2^40 declared values written
  edit_file(file_, [](hid_t f) {
    declare_dataset(f, "/bonds/tag", H5T_STD_I32LE, {hsize_t{1} << 40}, 1024, true, 1024);
  });
  expect_error({"cube.h5: /bonds/tag: declares 1099511627776 values (4398046511104 bytes)", "(compressed)"});

  write_h5(ten_particles(), file_);  // beyond what a size_t can count
  edit_file(file_, [](hid_t f) {
    declare_dataset(f, "/statistics/huge", H5T_IEEE_F64LE, {hsize_t{1} << 62}, 1, false, 0);
  });
  expect_error({"cube.h5: /statistics/huge: declares 4611686018427387904 values (over 2^64 bytes)"});

  write_h5(ten_particles(), file_);  // chunked and compressed, completely written: read as before
  edit_file(file_,
            [](hid_t f) { declare_dataset(f, "/particles/radius", H5T_IEEE_F64LE, {10}, 4, true, 10); });
  const auto g = read_h5(file_);
  EXPECT_EQ(g.radius, std::vector<double>(10, 0.5));
  GeometryFile sliced(file_);
  Geometry part;
  sliced.read_particles(3, 7, part);
  EXPECT_EQ(part.radius, std::vector<double>(4, 0.5));
}
