#pragma once
// A thin layer over the HDF5 C API shared by Basalt's HDF5 formats (geometry, checkpoint):
//  - handles that close themselves;
//  - HDF5's own error printing silenced, its error stack turned into FormatError messages that
//    name the file and the dataset or attribute;
//  - a Reader that reads whole datasets in one call each (fast for millions of particles) after
//    checking their type class and shape;
//  - a Writer that creates a temporary file, writes byte-for-byte deterministic content (no
//    object timestamps, fixed little-endian file types), then fsyncs and renames it into place.
// Files are opened serially with default property lists (no MPI-IO): one process per file.
#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <new>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "basalt/io/geometry.hpp"

namespace basalt::io::h5 {

namespace fs = std::filesystem;

/// Owns one HDF5 identifier and closes it with the matching H5?close function.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer close) : id_(id), close_(close) {}
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      close_ = o.close_;
      o.id_ = -1;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  /// Closes now; returns false when HDF5 reports an error on close.
  bool reset() {
    bool ok = true;
    if (id_ >= 0 && close_) ok = close_(id_) >= 0;
    id_ = -1;
    return ok;
  }

 private:
  hid_t id_ = -1;
  Closer close_ = nullptr;
};

/// Turns HDF5's automatic error-stack printing off while alive, restores it afterwards.
class QuietErrors {
 public:
  QuietErrors();
  ~QuietErrors();
  QuietErrors(const QuietErrors&) = delete;
  QuietErrors& operator=(const QuietErrors&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

/// The most specific message on HDF5's current error stack (e.g. "file signature not found"),
/// or "" when the stack is empty. Call it right after the failing HDF5 call.
std::string error_detail();

/// Memory and file types for the numeric types Basalt stores.
template <class T>
struct Type;
template <>
struct Type<std::int64_t> {
  static hid_t mem() { return H5T_NATIVE_INT64; }
  static hid_t file() { return H5T_STD_I64LE; }
};
template <>
struct Type<std::int32_t> {
  static hid_t mem() { return H5T_NATIVE_INT32; }
  static hid_t file() { return H5T_STD_I32LE; }
};
template <>
struct Type<std::uint8_t> {
  static hid_t mem() { return H5T_NATIVE_UINT8; }
  static hid_t file() { return H5T_STD_U8LE; }
};
template <>
struct Type<double> {
  static hid_t mem() { return H5T_NATIVE_DOUBLE; }
  static hid_t file() { return H5T_IEEE_F64LE; }
};

template <class T>
constexpr H5T_class_t type_class() {
  return std::is_floating_point_v<T> ? H5T_FLOAT : H5T_INTEGER;
}

/// Read access to one HDF5 file. Every failure throws FormatError(file, object, what).
class Reader {
 public:
  explicit Reader(const fs::path& file);
  const fs::path& file() const { return file_; }
  hid_t id() const { return file_id_.get(); }

  /// Throws FormatError naming the file and `where`, with HDF5's detail appended when there is one.
  [[noreturn]] void fail(const std::string& where, const std::string& what) const;

  /// True when an object (group or dataset) exists at the absolute path.
  bool exists(const std::string& path) const;
  /// Throws unless a group exists at `path`.
  void require_group(const std::string& path) const;
  /// Names of the links in a group, in HDF5's name order.
  std::vector<std::string> members(const std::string& group) const;
  bool is_dataset(const std::string& path) const;

  /// Rows of a numeric dataset after checking it exists, holds numbers of T's class (integer or
  /// floating point) and has shape (rows) for columns == 0 or (rows, columns) otherwise.
  template <class T>
  std::size_t rows(const std::string& dataset, std::size_t columns = 0) const {
    return checked_rows(dataset, type_class<T>(), columns);
  }
  /// Reads the whole dataset in one call into `out` (rows*columns values, converted to T).
  template <class T>
  void read_into(const std::string& dataset, T* out) const {
    read_raw(dataset, Type<T>::mem(), out);
  }
  /// Reads rows [row, row + count) of a dataset of `columns` columns (0: one-dimensional) into `out`
  /// (a hyperslab: only those rows are read from the file).
  template <class T>
  void read_rows_into(const std::string& dataset, std::size_t row, std::size_t count, std::size_t columns,
                      T* out) const {
    read_rows_raw(dataset, Type<T>::mem(), row, count, columns, out);
  }
  template <class T>
  std::vector<T> read(const std::string& dataset, std::size_t columns = 0) const {
    std::vector<T> v(rows<T>(dataset, columns) * (columns ? columns : 1));
    if (!v.empty()) read_into(dataset, v.data());
    return v;
  }

  bool has_attribute(const std::string& object, const std::string& name) const;
  std::vector<std::string> attribute_names(const std::string& object) const;
  bool attribute_is_string(const std::string& object, const std::string& name) const;
  std::string string_attribute(const std::string& object, const std::string& name) const;
  /// A numeric attribute with exactly `count` values (scalar when count == 1).
  template <class T>
  std::vector<T> numeric_attribute(const std::string& object, const std::string& name,
                                   std::size_t count) const {
    std::vector<T> v(count);
    read_numeric_attribute(object, name, type_class<T>(), Type<T>::mem(), count, v.data());
    return v;
  }
  template <class T>
  T scalar_attribute(const std::string& object, const std::string& name) const {
    return numeric_attribute<T>(object, name, 1)[0];
  }

  /// Closes the file; reports a close failure as an error.
  void close();

 private:
  std::size_t checked_rows(const std::string& dataset, H5T_class_t cls, std::size_t columns) const;
  /// Refuses a dataset declaring more values than the file stores (see kMaxFilterRatio).
  void check_storage(const std::string& dataset, hid_t ds, hid_t type,
                     const std::vector<hsize_t>& dims) const;
  /// The most a filtered (compressed) dataset may declare per byte stored: deflate's limit is about 1032:1.
  static constexpr hsize_t kMaxFilterRatio = 1100;
  void read_raw(const std::string& dataset, hid_t mem_type, void* out) const;
  void read_rows_raw(const std::string& dataset, hid_t mem_type, std::size_t row, std::size_t count,
                     std::size_t columns, void* out) const;
  void read_numeric_attribute(const std::string& object, const std::string& name, H5T_class_t cls,
                              hid_t mem_type, std::size_t count, void* out) const;
  Handle open_attribute(const std::string& object, const std::string& name) const;

  QuietErrors quiet_;  // declared first: errors stay silent until every handle below is closed
  fs::path file_;
  Handle file_id_;
};

/// Writes one HDF5 file under a temporary name; commit() closes, fsyncs and renames it to the
/// final name. Destroyed without commit() (an error was thrown), it removes the temporary file,
/// so nothing partial ever appears under the final name. Errors name the final file.
class Writer {
 public:
  Writer(const fs::path& file, const fs::path& temp);
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  const fs::path& file() const { return file_; }
  [[noreturn]] void fail(const std::string& where, const std::string& what) const;

  void group(const std::string& path);
  /// A dataset of shape (rows) for columns == 0, else (rows, columns), contiguous and uncompressed unless
  /// compress() was called.
  template <class T>
  void dataset(const std::string& path, const T* data, std::size_t rows, std::size_t columns = 0) {
    write_dataset(path, Type<T>::file(), Type<T>::mem(), data, rows, columns);
  }
  template <class T>
  void dataset(const std::string& path, const std::vector<T>& v) {
    dataset(path, v.data(), v.size());
  }
  /// A one-dimensional int64 dataset of `rows` values made slab by slab: fill(begin, out) sets out[k]
  /// to the value of row begin + k. Only one slab of kSlabRows values is held at a time (the file's
  /// image still grows with what is written: compress() first for a small one).
  using Int64Slab = std::function<void(std::size_t begin, std::span<std::int64_t> out)>;
  void int64_dataset_by_slabs(const std::string& path, std::size_t rows, const Int64Slab& fill);
  static constexpr std::size_t kSlabRows = 65536;  // a compressed chunk's rows for one column

  /// A UTF-8 variable-length string attribute.
  void attribute(const std::string& object, const std::string& name, const std::string& value);
  /// A numeric attribute: scalar when count == 1 and !as_array, else a 1-D array.
  template <class T>
  void attribute(const std::string& object, const std::string& name, const T* values, std::size_t count,
                 bool as_array = false) {
    write_numeric_attribute(object, name, Type<T>::file(), Type<T>::mem(), values, count, as_array);
  }
  template <class T>
  void scalar_attribute(const std::string& object, const std::string& name, T value) {
    attribute(object, name, &value, 1);
  }

  void commit();

  /// From now on, datasets of at least kCompressMinValues values are written chunked (about 64 Ki values
  /// per chunk) through HDF5's shuffle and deflate filters at `deflate_level` (1-9; 0: contiguous and
  /// uncompressed, the default). Deterministic: the same data gives the same bytes.
  void compress(int deflate_level);
  static constexpr std::size_t kCompressMinValues = 4096;

 private:
  void write_dataset(const std::string& path, hid_t file_type, hid_t mem_type, const void* data,
                     std::size_t rows, std::size_t columns);
  /// Creates (does not write) a dataset of that shape, with the compression filters when compress() asked.
  Handle create_dataset(const std::string& path, hid_t file_type, std::size_t rows, std::size_t columns);
  void write_numeric_attribute(const std::string& object, const std::string& name, hid_t file_type,
                               hid_t mem_type, const void* values, std::size_t count, bool as_array);

  QuietErrors quiet_;
  fs::path file_;
  fs::path temp_;
  Handle file_id_;
  Handle gcpl_;  // group creation: no timestamps
  Handle dcpl_;  // dataset creation: no timestamps, never write fill values
  int deflate_level_ = 0;
  bool committed_ = false;
};

/// Runs `read`, turning an allocation failure (a file declaring more values than memory holds or
/// than a vector can address) into a FormatError naming the file.
template <class F>
auto with_memory_guard(const fs::path& file, F&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const std::bad_alloc&) {
    throw FormatError(file, "", "not enough memory to hold the file's datasets");
  } catch (const std::length_error&) {
    throw FormatError(file, "", "a dataset declares more values than this machine can address");
  }
}

}  // namespace basalt::io::h5
