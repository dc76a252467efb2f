#include "h5_support.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <limits>
#include <span>
#include <vector>

namespace basalt::io::h5 {

namespace {

std::string attribute_where(const std::string& object, const std::string& name) {
  return fmt::format("attribute '{}' of {}", name, object);
}

const char* class_name(H5T_class_t c) {
  switch (c) {
    case H5T_INTEGER:
      return "integer";
    case H5T_FLOAT:
      return "floating-point";
    case H5T_STRING:
      return "string";
    case H5T_COMPOUND:
      return "compound";
    case H5T_ENUM:
      return "enum";
    case H5T_ARRAY:
      return "array";
    case H5T_VLEN:
      return "variable-length";
    default:
      return "non-numeric";
  }
}

std::string shape_text(const std::vector<hsize_t>& dims) {
  if (dims.empty()) return "a scalar";
  std::string s = "(";
  for (std::size_t k = 0; k < dims.size(); ++k) s += fmt::format("{}{}", k ? ", " : "", dims[k]);
  return s + ")";
}

// Makes HDF5 abort a read instead of silently clipping a value that does not fit the memory type.
H5T_conv_ret_t abort_on_overflow(H5T_conv_except_t except, hid_t, hid_t, void*, void*, void*) {
  if (except == H5T_CONV_EXCEPT_RANGE_HI || except == H5T_CONV_EXCEPT_RANGE_LOW) return H5T_CONV_ABORT;
  return H5T_CONV_UNHANDLED;
}

Handle string_type() {
  Handle t(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(t.get(), H5T_VARIABLE);
  H5Tset_cset(t.get(), H5T_CSET_UTF8);
  return t;
}

herr_t collect_link(hid_t, const char* name, const H5L_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->emplace_back(name);
  return 0;
}

herr_t collect_attribute(hid_t, const char* name, const H5A_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->emplace_back(name);
  return 0;
}

}  // namespace

QuietErrors::QuietErrors() {
  H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

QuietErrors::~QuietErrors() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

std::string error_detail() {
  std::string detail;
  auto innermost = [](unsigned n, const H5E_error2_t* e, void* out) -> herr_t {
    auto* s = static_cast<std::string*>(out);
    if (n == 0 && e->desc && *e->desc) *s = e->desc;
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, innermost, &detail);
  H5Eclear2(H5E_DEFAULT);
  return detail;
}

// ---------------------------------------------------------------------------------------------
// Reader

Reader::Reader(const fs::path& file) : file_(file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw FormatError(file, "", "no such file");
  if (fs::is_directory(file, ec)) throw FormatError(file, "", "is a folder, not a file");
  if (H5Fis_hdf5(file.c_str()) <= 0) {
    const auto detail = error_detail();
    throw FormatError(file, "", "not an HDF5 file" + (detail.empty() ? "" : " (HDF5: " + detail + ")"));
  }
  file_id_ = Handle(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file_id_.valid()) {
    const auto detail = error_detail();
    const bool truncated = detail.find("truncated") != std::string::npos;
    throw FormatError(
        file, "",
        fmt::format("{} (HDF5: {})", truncated ? "file is truncated" : "cannot open as HDF5", detail));
  }
}

void Reader::fail(const std::string& where, const std::string& what) const {
  const auto detail = error_detail();
  throw FormatError(file_, where, detail.empty() ? what : fmt::format("{} (HDF5: {})", what, detail));
}

bool Reader::exists(const std::string& path) const {
  if (path == "/") return true;
  // H5Lexists fails (rather than answering false) when an intermediate group is missing,
  // so walk the path one component at a time.
  std::size_t pos = 0;
  while (pos != std::string::npos) {
    pos = path.find('/', pos + 1);
    const auto prefix = path.substr(0, pos);
    if (H5Lexists(id(), prefix.c_str(), H5P_DEFAULT) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return false;
    }
  }
  const htri_t resolves = H5Oexists_by_name(id(), path.c_str(), H5P_DEFAULT);
  H5Eclear2(H5E_DEFAULT);
  return resolves > 0;
}

bool Reader::is_dataset(const std::string& path) const {
  if (!exists(path)) return false;
  Handle obj(H5Oopen(id(), path.c_str(), H5P_DEFAULT), H5Oclose);
  return obj.valid() && H5Iget_type(obj.get()) == H5I_DATASET;
}

void Reader::require_group(const std::string& path) const {
  if (!exists(path)) fail(path, "missing group");
  Handle obj(H5Oopen(id(), path.c_str(), H5P_DEFAULT), H5Oclose);
  if (!obj.valid()) fail(path, "cannot open");
  if (H5Iget_type(obj.get()) != H5I_GROUP) fail(path, "expected a group");
}

std::vector<std::string> Reader::members(const std::string& group) const {
  require_group(group);
  std::vector<std::string> names;
  if (H5Literate_by_name(id(), group.c_str(), H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_link, &names,
                         H5P_DEFAULT) < 0)
    fail(group, "cannot list the group's members");
  return names;
}

std::size_t Reader::checked_rows(const std::string& dataset, H5T_class_t cls, std::size_t columns) const {
  if (!exists(dataset)) fail(dataset, "missing dataset");
  if (!is_dataset(dataset)) fail(dataset, "expected a dataset, found another kind of object");
  Handle ds(H5Dopen2(id(), dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) fail(dataset, "cannot open dataset");
  Handle type(H5Dget_type(ds.get()), H5Tclose);
  const H5T_class_t found = H5Tget_class(type.get());
  if (found != cls)
    fail(dataset, fmt::format("expected {} values, found {} values", class_name(cls), class_name(found)));
  Handle space(H5Dget_space(ds.get()), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0) fail(dataset, "cannot read the dataset's shape");
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  const bool ok = columns == 0 ? rank == 1 : (rank == 2 && dims[1] == columns);
  if (!ok)
    fail(dataset, fmt::format("expected shape {}, found {}",
                              columns == 0 ? "(N)" : fmt::format("(N, {})", columns), shape_text(dims)));
  check_storage(dataset, ds.get(), type.get(), dims);
  return static_cast<std::size_t>(dims[0]);
}

void Reader::check_storage(const std::string& dataset, hid_t ds, hid_t type,
                           const std::vector<hsize_t>& dims) const {
  // HDF5 answers a read of storage never written with fill values, so a file of a few KB can declare
  // 2^40 values and have the reader allocate them all. Every value declared must be in the file: as
  // many bytes stored as declared, or, through filters, at most kMaxFilterRatio times fewer (deflate's
  // ratio cannot exceed about 1032:1). That bounds what a reader allocates by the file's size.
  constexpr hsize_t max = std::numeric_limits<hsize_t>::max();
  if (std::find(dims.begin(), dims.end(), hsize_t{0}) != dims.end()) return;  // no values
  hsize_t values = 1;
  for (auto d : dims) values = values > max / d ? max : values * d;
  const hsize_t type_size = std::max<hsize_t>(H5Tget_size(type), 1);
  const hsize_t declared = values > max / type_size ? max : values * type_size;
  const hsize_t stored = H5Dget_storage_size(ds);
  Handle dcpl(H5Dget_create_plist(ds), H5Pclose);
  const int filters = dcpl.valid() ? H5Pget_nfilters(dcpl.get()) : 0;
  const hsize_t ratio = filters > 0 ? kMaxFilterRatio : 1;
  if (stored < declared / ratio + (declared % ratio != 0))
    fail(dataset,
         fmt::format("declares {} values ({} bytes) but the file holds {} bytes of them{}: the file is "
                     "damaged or the dataset was never completely written",
                     values, declared == max ? std::string("over 2^64") : std::to_string(declared), stored,
                     filters > 0 ? " (compressed)" : ""));
}

void Reader::read_raw(const std::string& dataset, hid_t mem_type, void* out) const {
  Handle ds(H5Dopen2(id(), dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) fail(dataset, "cannot open dataset");
  Handle dxpl(H5Pcreate(H5P_DATASET_XFER), H5Pclose);
  H5Pset_type_conv_cb(dxpl.get(), abort_on_overflow, nullptr);
  if (H5Dread(ds.get(), mem_type, H5S_ALL, H5S_ALL, dxpl.get(), out) < 0)
    fail(dataset, "cannot read the values (file damaged, or a value out of range for its type)");
}

void Reader::read_rows_raw(const std::string& dataset, hid_t mem_type, std::size_t row, std::size_t count,
                           std::size_t columns, void* out) const {
  if (count == 0) return;
  Handle ds(H5Dopen2(id(), dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) fail(dataset, "cannot open dataset");
  Handle file_space(H5Dget_space(ds.get()), H5Sclose);
  const int rank = columns == 0 ? 1 : 2;
  const hsize_t start[2] = {static_cast<hsize_t>(row), 0};
  const hsize_t size[2] = {static_cast<hsize_t>(count), static_cast<hsize_t>(columns)};
  if (H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, size, nullptr) < 0)
    fail(dataset, fmt::format("cannot select rows {} to {}", row, row + count));
  Handle mem_space(H5Screate_simple(rank, size, nullptr), H5Sclose);
  Handle dxpl(H5Pcreate(H5P_DATASET_XFER), H5Pclose);
  H5Pset_type_conv_cb(dxpl.get(), abort_on_overflow, nullptr);
  if (H5Dread(ds.get(), mem_type, mem_space.get(), file_space.get(), dxpl.get(), out) < 0)
    fail(dataset,
         fmt::format("cannot read rows {} to {} (file damaged, or a value out of range for its type)", row,
                     row + count));
}

bool Reader::has_attribute(const std::string& object, const std::string& name) const {
  if (!exists(object)) return false;
  const htri_t r = H5Aexists_by_name(id(), object.c_str(), name.c_str(), H5P_DEFAULT);
  H5Eclear2(H5E_DEFAULT);
  return r > 0;
}

std::vector<std::string> Reader::attribute_names(const std::string& object) const {
  std::vector<std::string> names;
  if (H5Aiterate_by_name(id(), object.c_str(), H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_attribute, &names,
                         H5P_DEFAULT) < 0)
    fail(object, "cannot list attributes");
  return names;
}

Handle Reader::open_attribute(const std::string& object, const std::string& name) const {
  if (!has_attribute(object, name)) fail(attribute_where(object, name), "missing attribute");
  Handle a(H5Aopen_by_name(id(), object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!a.valid()) fail(attribute_where(object, name), "cannot open attribute");
  return a;
}

bool Reader::attribute_is_string(const std::string& object, const std::string& name) const {
  auto a = open_attribute(object, name);
  Handle type(H5Aget_type(a.get()), H5Tclose);
  return H5Tget_class(type.get()) == H5T_STRING;
}

std::string Reader::string_attribute(const std::string& object, const std::string& name) const {
  const auto where = attribute_where(object, name);
  auto a = open_attribute(object, name);
  Handle type(H5Aget_type(a.get()), H5Tclose);
  const H5T_class_t cls = H5Tget_class(type.get());
  if (cls != H5T_STRING) fail(where, fmt::format("expected a string, found {} values", class_name(cls)));
  Handle space(H5Aget_space(a.get()), H5Sclose);
  if (H5Sget_simple_extent_npoints(space.get()) != 1) fail(where, "expected a single string");
  if (H5Tis_variable_str(type.get()) > 0) {
    Handle mem = string_type();
    char* text = nullptr;
    if (H5Aread(a.get(), mem.get(), &text) < 0) fail(where, "cannot read");
    std::string value = text ? text : "";
    H5free_memory(text);
    return value;
  }
  const std::size_t size = H5Tget_size(type.get());
  Handle mem(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(mem.get(), size);
  std::string value(size, '\0');
  if (H5Aread(a.get(), mem.get(), value.data()) < 0) fail(where, "cannot read");
  value.resize(value.find('\0') == std::string::npos ? size : value.find('\0'));
  return value;
}

void Reader::read_numeric_attribute(const std::string& object, const std::string& name, H5T_class_t cls,
                                    hid_t mem_type, std::size_t count, void* out) const {
  const auto where = attribute_where(object, name);
  auto a = open_attribute(object, name);
  Handle type(H5Aget_type(a.get()), H5Tclose);
  const H5T_class_t found = H5Tget_class(type.get());
  if (found != cls)
    fail(where, fmt::format("expected {} values, found {} values", class_name(cls), class_name(found)));
  Handle space(H5Aget_space(a.get()), H5Sclose);
  const auto n = H5Sget_simple_extent_npoints(space.get());
  if (n != static_cast<hssize_t>(count)) fail(where, fmt::format("expected {} value(s), found {}", count, n));
  if (H5Aread(a.get(), mem_type, out) < 0) fail(where, "cannot read (a value out of range for its type?)");
}

void Reader::close() {
  if (!file_id_.reset()) fail("", "cannot close");
}

// ---------------------------------------------------------------------------------------------
// Writer

Writer::Writer(const fs::path& file, const fs::path& temp) : file_(file), temp_(temp) {
  // No object may record its creation/modification time: identical input gives identical bytes.
  Handle fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  H5Pset_obj_track_times(fcpl.get(), false);
  gcpl_ = Handle(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
  H5Pset_obj_track_times(gcpl_.get(), false);
  dcpl_ = Handle(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_obj_track_times(dcpl_.get(), false);
  H5Pset_fill_time(dcpl_.get(), H5D_FILL_TIME_NEVER);
  if (!fcpl.valid() || !gcpl_.valid() || !dcpl_.valid()) fail("", "cannot set up HDF5 property lists");

  const fs::path folder = temp.has_parent_path() ? temp.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::exists(folder, ec))
    fail("", fmt::format("cannot create: folder '{}' does not exist", folder.string()));
  if (!fs::is_directory(folder, ec))
    fail("", fmt::format("cannot create: '{}' is not a folder", folder.string()));
  // The file is built in memory (core driver, no backing store) and written by commit() with plain
  // POSIX calls: a full disk or a file-size limit then fails there with errno, named, and HDF5 never
  // holds a half-written file it cannot close (it would crash at exit).
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!fapl.valid() || H5Pset_fapl_core(fapl.get(), 4 << 20, 0) < 0)
    fail("", "cannot set up the in-memory HDF5 file");
  file_id_ = Handle(H5Fcreate(temp.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()), H5Fclose);
  if (!file_id_.valid())
    fail("", fmt::format("cannot create '{}' (does the folder exist and is it writable?)", temp.string()));
}

Writer::~Writer() {
  if (committed_) return;
  file_id_.reset();
  H5Eclear2(H5E_DEFAULT);
  std::error_code ec;
  fs::remove(temp_, ec);
}

void Writer::fail(const std::string& where, const std::string& what) const {
  const auto detail = error_detail();
  throw FormatError(file_, where, detail.empty() ? what : fmt::format("{} (HDF5: {})", what, detail));
}

void Writer::group(const std::string& path) {
  Handle g(H5Gcreate2(file_id_.get(), path.c_str(), H5P_DEFAULT, gcpl_.get(), H5P_DEFAULT), H5Gclose);
  if (!g.valid()) fail(path, "cannot create group");
}

Handle Writer::create_dataset(const std::string& path, hid_t file_type, std::size_t rows,
                              std::size_t columns) {
  const hsize_t dims[2] = {rows, columns};
  Handle space(H5Screate_simple(columns ? 2 : 1, dims, nullptr), H5Sclose);
  if (!space.valid()) fail(path, "cannot create dataspace");
  Handle dcpl(H5Pcopy(dcpl_.get()), H5Pclose);
  const std::size_t values = rows * (columns ? columns : 1);
  if (deflate_level_ > 0 && values >= kCompressMinValues) {
    const hsize_t width = columns ? columns : 1;
    const hsize_t chunk[2] = {std::max<hsize_t>(1, std::min<hsize_t>(rows, 65536 / width)), width};
    if (H5Pset_chunk(dcpl.get(), columns ? 2 : 1, chunk) < 0 || H5Pset_shuffle(dcpl.get()) < 0 ||
        H5Pset_deflate(dcpl.get(), static_cast<unsigned>(deflate_level_)) < 0)
      fail(path, "cannot set up the compression filters");
  }
  Handle ds(
      H5Dcreate2(file_id_.get(), path.c_str(), file_type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
      H5Dclose);
  if (!ds.valid()) fail(path, "cannot create dataset");
  return ds;
}

void Writer::write_dataset(const std::string& path, hid_t file_type, hid_t mem_type, const void* data,
                           std::size_t rows, std::size_t columns) {
  Handle ds = create_dataset(path, file_type, rows, columns);
  if (rows * (columns ? columns : 1) > 0 &&
      H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    fail(path, "cannot write dataset (disk full?)");
  if (!ds.reset()) fail(path, "cannot close dataset (disk full?)");
}

void Writer::int64_dataset_by_slabs(const std::string& path, std::size_t rows, const Int64Slab& fill) {
  static_assert(kSlabRows == 65536, "a slab is one compressed chunk (create_dataset): each is written once");
  Handle ds = create_dataset(path, Type<std::int64_t>::file(), rows, 0);
  Handle file_space(H5Dget_space(ds.get()), H5Sclose);
  if (!file_space.valid()) fail(path, "cannot get dataspace");
  std::vector<std::int64_t> slab(std::min(rows, kSlabRows));
  for (std::size_t begin = 0; begin < rows; begin += kSlabRows) {
    const std::size_t count = std::min(kSlabRows, rows - begin);
    fill(begin, std::span<std::int64_t>(slab.data(), count));
    const hsize_t start[1] = {begin}, n[1] = {count};
    Handle mem_space(H5Screate_simple(1, n, nullptr), H5Sclose);
    if (!mem_space.valid() ||
        H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, n, nullptr) < 0 ||
        H5Dwrite(ds.get(), Type<std::int64_t>::mem(), mem_space.get(), file_space.get(), H5P_DEFAULT,
                 slab.data()) < 0)
      fail(path, fmt::format("cannot write rows {} to {}", begin, begin + count));
  }
  if (!ds.reset()) fail(path, "cannot close dataset (disk full?)");
}

void Writer::compress(int deflate_level) {
  if (deflate_level < 0 || deflate_level > 9)
    fail("", fmt::format("deflate level {} is not in 0..9", deflate_level));
  if (deflate_level > 0 &&
      (H5Zfilter_avail(H5Z_FILTER_DEFLATE) <= 0 || H5Zfilter_avail(H5Z_FILTER_SHUFFLE) <= 0))
    fail("", "this HDF5 library has no deflate (zlib) or shuffle filter: use compression = \"none\"");
  deflate_level_ = deflate_level;
}

void Writer::attribute(const std::string& object, const std::string& name, const std::string& value) {
  const auto where = attribute_where(object, name);
  if (value.find('\0') != std::string::npos) fail(where, "string contains a NUL character");
  Handle type = string_type();
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle a(H5Acreate_by_name(file_id_.get(), object.c_str(), name.c_str(), type.get(), space.get(),
                             H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
           H5Aclose);
  if (!a.valid()) fail(where, "cannot create attribute");
  const char* text = value.c_str();
  if (H5Awrite(a.get(), type.get(), &text) < 0) fail(where, "cannot write attribute");
}

void Writer::write_numeric_attribute(const std::string& object, const std::string& name, hid_t file_type,
                                     hid_t mem_type, const void* values, std::size_t count, bool as_array) {
  const auto where = attribute_where(object, name);
  const hsize_t dims[1] = {count};
  Handle space(count == 1 && !as_array ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, dims, nullptr),
               H5Sclose);
  Handle a(H5Acreate_by_name(file_id_.get(), object.c_str(), name.c_str(), file_type, space.get(),
                             H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
           H5Aclose);
  if (!a.valid()) fail(where, "cannot create attribute");
  if (H5Awrite(a.get(), mem_type, values) < 0) fail(where, "cannot write attribute");
}

void Writer::commit() {
  if (H5Fflush(file_id_.get(), H5F_SCOPE_GLOBAL) < 0) fail("", "cannot finish the file in memory");
  const ssize_t size = H5Fget_file_image(file_id_.get(), nullptr, 0);
  if (size < 0) fail("", "cannot take the file image");
  // Write the core driver's own buffer (its handle is the address of the buffer's pointer): a copy
  // of the image would double the memory a large checkpoint needs. The file is closed afterwards.
  void* handle = nullptr;
  if (H5Fget_vfd_handle(file_id_.get(), H5P_DEFAULT, &handle) < 0 || handle == nullptr ||
      *static_cast<unsigned char**>(handle) == nullptr)
    fail("", "cannot take the file image");
  const std::span<const char> image(reinterpret_cast<const char*>(*static_cast<unsigned char**>(handle)),
                                    static_cast<std::size_t>(size));
  // The superblock's first bytes go from a copy with its status flags cleared, as H5Fget_file_image
  // clears them (the open file marks itself open for writing there): the same bytes as its image.
  std::array<char, 64> head{};
  const std::size_t head_size = std::min(head.size(), image.size());
  std::copy_n(image.data(), head_size, head.data());
  if (head_size > 8) {
    const int version = static_cast<unsigned char>(head[8]);  // after the 8-byte signature
    const std::size_t flags = version >= 2 ? 11 : 20, flags_size = version >= 2 ? 1 : 4;
    if (flags + flags_size <= head_size) std::fill_n(head.data() + flags, flags_size, '\0');
  }
  // Write, then make the bytes durable before the rename makes them visible under the final name.
  const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) fail("", fmt::format("cannot create '{}': {}", temp_.string(), std::strerror(errno)));
  std::size_t done = 0;
  while (done < image.size()) {
    const bool in_head = done < head_size;
    const ssize_t n = ::write(fd, (in_head ? head.data() : image.data()) + done,
                              (in_head ? head_size : image.size()) - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = n < 0 ? errno : ENOSPC;
      ::close(fd);
      fail("", fmt::format("cannot write '{}' ({} of {} bytes written): {}", temp_.string(), done,
                           image.size(), std::strerror(err)));
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    fail("", fmt::format("cannot sync '{}' to disk: {}", temp_.string(), std::strerror(err)));
  }
  if (::close(fd) != 0) fail("", fmt::format("cannot close '{}': {}", temp_.string(), std::strerror(errno)));
  if (!file_id_.reset()) fail("", "cannot close the in-memory file");
  std::error_code ec;
  fs::rename(temp_, file_, ec);
  if (ec) fail("", fmt::format("cannot rename '{}' into place: {}", temp_.string(), ec.message()));
  committed_ = true;
  // Persist the rename itself (best effort: some filesystems refuse fsync on a folder).
  const auto dir = file_.has_parent_path() ? file_.parent_path() : fs::path(".");
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace basalt::io::h5
