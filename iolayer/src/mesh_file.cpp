// Triangle-mesh readers: ASCII and binary STL, Wavefront OBJ, OFF; then one welding and validation pass
// shared by all formats (basalt/io/mesh_file.hpp, docs/mesh-walls.md).
#include "basalt/io/mesh_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string_view>
#include <unordered_map>

namespace basalt::io {

namespace fs = std::filesystem;

namespace {

/// What the parsers produce: raw vertices, triangles indexing them, and where each triangle came from.
struct RawMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::int32_t, 3>> triangles;
  std::vector<std::uint64_t> origin;  ///< line number, or byte offset for binary STL
  bool binary = false;

  std::string where(std::size_t t) const {
    return binary ? fmt::format("byte offset {}", origin[t]) : fmt::format("line {}", origin[t]);
  }
};

std::string read_all(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw FormatError(file, "", "no such file");
  if (fs::is_directory(file, ec)) throw FormatError(file, "", "is a folder, not a file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw FormatError(file, "", "cannot open for reading");
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Splits a text into lines and lines into whitespace-separated fields; errors name the line.
class TextLines {
 public:
  TextLines(const fs::path& file, std::string_view text) : file_(file), text_(text) {}

  /// Next line with at least one field (after removing `comment` and what follows); false at the end.
  bool next(char comment = '#') {
    while (pos_ < text_.size()) {
      std::size_t end = text_.find('\n', pos_);
      if (end == std::string_view::npos) end = text_.size();
      std::string_view line = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_no_;
      if (const auto c = line.find(comment); c != std::string_view::npos) line = line.substr(0, c);
      split(line);
      if (!fields_.empty()) return true;
    }
    fields_.clear();
    return false;
  }

  const std::vector<std::string_view>& fields() const { return fields_; }
  std::size_t line() const { return line_no_; }

  [[noreturn]] void fail(const std::string& what) const {
    throw FormatError(file_, fmt::format("line {}", line_no_), what);
  }
  [[noreturn]] void fail_at_end(const std::string& expected) const {
    throw FormatError(file_, fmt::format("line {}", line_no_ + 1),
                      fmt::format("unexpected end of file, expected {}", expected));
  }

  double coordinate(std::string_view s) const {
    double v = 0;
    const char* end = s.data() + s.size();
    auto [p, ec] = std::from_chars(s.data(), end, v);
    if (ec == std::errc::result_out_of_range) fail(fmt::format("coordinate '{}' is out of range", s));
    if (ec != std::errc() || p != end) fail(fmt::format("coordinate '{}' is not a valid number", s));
    if (!std::isfinite(v)) fail(fmt::format("coordinate '{}' is not finite", s));
    return v;
  }

  long long integer(std::string_view s, const char* what) const {
    long long v = 0;
    const char* end = s.data() + s.size();
    auto [p, ec] = std::from_chars(s.data(), end, v);
    if (ec != std::errc() || p != end) fail(fmt::format("{} '{}' is not a valid integer", what, s));
    return v;
  }

  Vec3 point(std::size_t first) const {
    if (fields_.size() < first + 3)
      fail(fmt::format("a vertex needs 3 coordinates, found {}", fields_.size() - first));
    return {coordinate(fields_[first]), coordinate(fields_[first + 1]), coordinate(fields_[first + 2])};
  }

 private:
  void split(std::string_view line) {
    fields_.clear();
    std::size_t i = 0;
    auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; };
    while (i < line.size()) {
      while (i < line.size() && space(line[i])) ++i;
      std::size_t j = i;
      while (j < line.size() && !space(line[j])) ++j;
      if (j > i) fields_.push_back(line.substr(i, j - i));
      i = j;
    }
  }

  const fs::path& file_;
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_no_ = 0;
  std::vector<std::string_view> fields_;
};

void add_polygon(RawMesh& m, const std::vector<std::int32_t>& poly, std::uint64_t origin) {
  for (std::size_t k = 1; k + 1 < poly.size(); ++k) {  // fan from the first vertex
    m.triangles.push_back({poly[0], poly[k], poly[k + 1]});
    m.origin.push_back(origin);
  }
}

// ---- STL -------------------------------------------------------------------------------------------

RawMesh parse_ascii_stl(const fs::path& file, std::string_view text) {
  RawMesh m;
  TextLines in(file, text);
  // No comments in STL: use a character that cannot occur in it.
  auto next = [&](const char* expected) {
    if (!in.next('\0')) in.fail_at_end(expected);
    return in.fields();
  };
  auto expect = [&](std::string_view kw, std::string_view kw2 = {}) {
    const auto& f = next(kw2.empty() ? std::string(kw).c_str() : fmt::format("{} {}", kw, kw2).c_str());
    if (f[0] != kw || (!kw2.empty() && (f.size() < 2 || f[1] != kw2)))
      in.fail(fmt::format("expected '{}{}{}', found '{}{}{}'", kw, kw2.empty() ? "" : " ", kw2, f[0],
                          f.size() > 1 ? " " : "", f.size() > 1 ? f[1] : std::string_view()));
  };
  bool any_solid = false;
  while (in.next('\0')) {
    if (in.fields()[0] != "solid")
      in.fail(fmt::format("expected 'solid'{}, found '{}'", any_solid ? " or the end of the file" : "",
                          in.fields()[0]));
    any_solid = true;
    for (;;) {
      const auto& f = next("'facet' or 'endsolid'");
      if (f[0] == "endsolid") break;
      if (f[0] != "facet") in.fail(fmt::format("expected 'facet' or 'endsolid', found '{}'", f[0]));
      const std::uint64_t facet_line = in.line();
      expect("outer", "loop");
      std::vector<std::int32_t> poly;
      for (;;) {
        const auto& v = next("'vertex' or 'endloop'");
        if (v[0] == "endloop") break;
        if (v[0] != "vertex") in.fail(fmt::format("expected 'vertex' or 'endloop', found '{}'", v[0]));
        if (v.size() != 4) in.fail(fmt::format("'vertex' takes 3 coordinates, found {}", v.size() - 1));
        m.vertices.push_back(in.point(1));
        poly.push_back(static_cast<std::int32_t>(m.vertices.size() - 1));
      }
      if (poly.size() != 3)
        in.fail(fmt::format("facet at line {} has {} vertices, expected 3", facet_line, poly.size()));
      expect("endfacet");
      add_polygon(m, poly, facet_line);
    }
  }
  if (!any_solid) throw FormatError(file, "", "empty file");
  return m;
}

std::uint32_t le32(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
         std::uint32_t(p[3]) << 24;
}

RawMesh parse_binary_stl(const fs::path& file, std::string_view bytes) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data());
  const std::uint64_t n = le32(b + 80);
  const std::uint64_t need = 84 + 50 * n;
  if (bytes.size() < need) {
    const std::uint64_t complete = (bytes.size() - 84) / 50;
    throw FormatError(
        file, fmt::format("byte offset {}", 84 + 50 * complete),
        fmt::format("truncated binary STL: the header announces {} triangles ({} bytes), the file has "
                    "{} bytes; triangle {} is incomplete",
                    n, need, bytes.size(), complete));
  }
  if (bytes.size() > need)
    throw FormatError(file, fmt::format("byte offset {}", need),
                      fmt::format("binary STL with {} bytes after the {} triangles its header announces",
                                  bytes.size() - need, n));
  RawMesh m;
  m.binary = true;
  m.vertices.reserve(3 * n);
  for (std::uint64_t t = 0; t < n; ++t) {
    const std::uint64_t at = 84 + 50 * t;
    for (int k = 0; k < 3; ++k) {
      Vec3 v{};
      for (int d = 0; d < 3; ++d) {
        const std::uint64_t off = at + 12 + 12 * k + 4 * d;
        const float x = std::bit_cast<float>(le32(b + off));
        if (!std::isfinite(x))
          throw FormatError(file, fmt::format("byte offset {}", off),
                            fmt::format("triangle {}: coordinate is not finite ({})", t, x));
        v[d] = x;
      }
      m.vertices.push_back(v);
    }
    const auto i = static_cast<std::int32_t>(3 * t);
    m.triangles.push_back({i, i + 1, i + 2});
    m.origin.push_back(at);
  }
  return m;
}

RawMesh parse_stl(const fs::path& file, std::string_view bytes) {
  if (bytes.size() >= 84) {
    const std::uint64_t n = le32(reinterpret_cast<const unsigned char*>(bytes.data()) + 80);
    if (bytes.size() == 84 + 50 * n) return parse_binary_stl(file, bytes);
  }
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  // "solid" starts ASCII STL, and some binary headers too: text has no control characters.
  const bool text = std::none_of(bytes.begin(), bytes.end(), [](char ch) {
    const auto u = static_cast<unsigned char>(ch);
    return u < 9 || (u > 13 && u < 32) || u == 127;
  });
  if (text && bytes.substr(i, 5) == "solid") return parse_ascii_stl(file, bytes);
  if (bytes.size() < 84)
    throw FormatError(file, fmt::format("byte offset {}", bytes.size()),
                      fmt::format("{} bytes: too short for a binary STL (84-byte header) and not ASCII STL "
                                  "(no 'solid' at the start)",
                                  bytes.size()));
  return parse_binary_stl(file, bytes);  // reports the size mismatch
}

// ---- OBJ -------------------------------------------------------------------------------------------

RawMesh parse_obj(const fs::path& file, std::string_view text) {
  RawMesh m;
  TextLines in(file, text);
  std::vector<std::int32_t> poly;
  while (in.next('#')) {
    const auto& f = in.fields();
    if (f[0] == "v") {
      m.vertices.push_back(in.point(1));  // an optional w or colour after x y z is ignored
    } else if (f[0] == "f") {
      if (f.size() < 4) in.fail(fmt::format("a face needs at least 3 vertices, found {}", f.size() - 1));
      poly.clear();
      const auto nv = static_cast<long long>(m.vertices.size());
      for (std::size_t k = 1; k < f.size(); ++k) {
        const auto ref = f[k].substr(0, f[k].find('/'));  // v, v/vt, v//vn, v/vt/vn
        const long long i = in.integer(ref, "vertex index");
        const long long idx = i < 0 ? nv + i : i - 1;  // 1-based; negative counts back from the last vertex
        if (i == 0 || idx < 0 || idx >= nv)
          in.fail(fmt::format("vertex index {} is out of range ({} vertices defined so far)", i, nv));
        poly.push_back(static_cast<std::int32_t>(idx));
      }
      add_polygon(m, poly, in.line());
    }
    // vt, vn, vp, g, o, s, l, p, usemtl, mtllib ...: not geometry a wall needs.
  }
  return m;
}

// ---- OFF -------------------------------------------------------------------------------------------

RawMesh parse_off(const fs::path& file, std::string_view text) {
  RawMesh m;
  TextLines in(file, text);
  if (!in.next('#')) throw FormatError(file, "", "empty file");
  std::size_t first = 0;  // counts may follow the keyword on its line
  if (in.fields()[0] != "OFF") in.fail(fmt::format("expected 'OFF', found '{}'", in.fields()[0]));
  first = 1;
  if (in.fields().size() == 1) {
    if (!in.next('#')) in.fail_at_end("vertex, face and edge counts");
    first = 0;
  }
  const auto& c = in.fields();
  if (c.size() - first < 2) in.fail("expected the vertex, face and edge counts");
  const long long nv = in.integer(c[first], "vertex count");
  const long long nf = in.integer(c[first + 1], "face count");
  if (nv < 0 || nf < 0 || nv > INT32_MAX) in.fail("vertex or face count out of range");
  m.vertices.reserve(static_cast<std::size_t>(nv));
  for (long long k = 0; k < nv; ++k) {
    if (!in.next('#')) in.fail_at_end(fmt::format("vertex {} of {}", k + 1, nv));
    m.vertices.push_back(in.point(0));
  }
  std::vector<std::int32_t> poly;
  for (long long k = 0; k < nf; ++k) {
    if (!in.next('#')) in.fail_at_end(fmt::format("face {} of {}", k + 1, nf));
    const auto& f = in.fields();
    const long long n = in.integer(f[0], "face vertex count");
    if (n < 3) in.fail(fmt::format("a face needs at least 3 vertices, found {}", n));
    if (static_cast<long long>(f.size()) - 1 < n)
      in.fail(fmt::format("face of {} vertices lists {} indices", n, f.size() - 1));
    poly.clear();
    for (long long j = 1; j <= n; ++j) {
      const long long i = in.integer(f[static_cast<std::size_t>(j)], "vertex index");
      if (i < 0 || i >= nv) in.fail(fmt::format("vertex index {} is out of range (0 to {})", i, nv - 1));
      poly.push_back(static_cast<std::int32_t>(i));
    }
    add_polygon(m, poly, in.line());  // a colour after the indices is ignored
  }
  return m;
}

// ---- welding and validation ------------------------------------------------------------------------

struct ExactKey {
  std::array<std::uint64_t, 3> bits;
  bool operator==(const ExactKey&) const = default;
};
struct ExactHash {
  std::size_t operator()(const ExactKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (auto b : k.bits) h = (h ^ b) * 1099511628211ull ^ (b >> 29);
    return static_cast<std::size_t>(h);
  }
};

ExactKey exact_key(const Vec3& v) {
  ExactKey k{};
  for (int d = 0; d < 3; ++d) k.bits[d] = std::bit_cast<std::uint64_t>(v[d] == 0.0 ? 0.0 : v[d]);
  return k;
}

/// rep[i]: the vertex that vertex i is merged into (rep[rep[i]] == rep[i]).
std::vector<std::int32_t> weld(const std::vector<Vec3>& v, double tolerance) {
  std::vector<std::int32_t> rep(v.size());
  std::unordered_map<ExactKey, std::int32_t, ExactHash> exact;
  exact.reserve(v.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    rep[i] = exact.try_emplace(exact_key(v[i]), static_cast<std::int32_t>(i)).first->second;
  if (tolerance <= 0 || v.empty()) return rep;

  Vec3 lo = v[0], hi = v[0];
  for (const auto& p : v)
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], p[d]), hi[d] = std::max(hi[d], p[d]);
  const double diag = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  const double tol = tolerance * diag;
  if (!(tol > 0)) return rep;
  // Hash grid of cell size tol over the exact representatives; each vertex joins the first
  // representative (in file order) within tol, searched in the 27 cells around it.
  struct CellHash {
    std::size_t operator()(const std::array<std::int64_t, 3>& c) const {
      return static_cast<std::size_t>(c[0] * 73856093 ^ c[1] * 19349663 ^ c[2] * 83492791);
    }
  };
  std::unordered_map<std::array<std::int64_t, 3>, std::vector<std::int32_t>, CellHash> cells;
  auto cell_of = [&](const Vec3& p) {
    std::array<std::int64_t, 3> c{};
    for (int d = 0; d < 3; ++d) c[d] = static_cast<std::int64_t>(std::floor((p[d] - lo[d]) / tol));
    return c;
  };
  std::vector<std::int32_t> near(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (rep[i] != static_cast<std::int32_t>(i)) continue;
    const auto c = cell_of(v[i]);
    std::int32_t best = static_cast<std::int32_t>(i);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (it == cells.end()) continue;
          for (const auto j : it->second) {
            const auto& q = v[static_cast<std::size_t>(j)];
            if (j < best && std::hypot(q[0] - v[i][0], q[1] - v[i][1], q[2] - v[i][2]) <= tol) best = j;
          }
        }
    near[i] = best;
    if (best == static_cast<std::int32_t>(i)) cells[c].push_back(best);
  }
  for (std::size_t i = 0; i < v.size(); ++i) rep[i] = near[static_cast<std::size_t>(rep[i])];
  return rep;
}

bool degenerate(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const Vec3 x{u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  auto sq = [](const Vec3& p) { return p[0] * p[0] + p[1] * p[1] + p[2] * p[2]; };
  const Vec3 e{c[0] - b[0], c[1] - b[1], c[2] - b[2]};
  const double longest = std::max({sq(u), sq(w), sq(e)});
  return std::sqrt(sq(x)) <= 1e-12 * longest;
}

TriangleMesh finish(const fs::path& file, const RawMesh& raw, const MeshReadOptions& opt) {
  if (!(opt.weld_tolerance >= 0 && opt.weld_tolerance < 1))
    throw FormatError(file, "", fmt::format("weld tolerance {} is not in [0, 1)", opt.weld_tolerance));
  TriangleMesh mesh;
  mesh.vertices_read = raw.vertices.size();
  mesh.triangles_read = raw.triangles.size();
  const auto rep = weld(raw.vertices, opt.weld_tolerance);
  std::vector<std::int32_t> new_index(raw.vertices.size(), -1);
  for (std::size_t t = 0; t < raw.triangles.size(); ++t) {
    std::array<std::int32_t, 3> tri{};
    for (int k = 0; k < 3; ++k) tri[k] = rep[static_cast<std::size_t>(raw.triangles[t][k])];
    const bool bad = tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] ||
                     degenerate(raw.vertices[tri[0]], raw.vertices[tri[1]], raw.vertices[tri[2]]);
    if (bad) {
      if (opt.degenerate == MeshReadOptions::Degenerate::refuse)
        throw FormatError(file, raw.where(t), "degenerate (zero-area) triangle");
      if (mesh.dropped_degenerate++ == 0) mesh.first_degenerate_where = raw.where(t);
      continue;
    }
    for (auto& i : tri) {
      auto& ni = new_index[static_cast<std::size_t>(i)];
      if (ni < 0) {
        ni = static_cast<std::int32_t>(mesh.vertices.size());
        mesh.vertices.push_back(raw.vertices[static_cast<std::size_t>(i)]);
      }
      i = ni;
    }
    mesh.triangles.push_back(tri);
  }
  if (mesh.triangles.empty())
    throw FormatError(
        file, "",
        raw.triangles.empty()
            ? std::string("no triangles in the mesh")
            : fmt::format("no triangles in the mesh: all {} are degenerate (zero area), the first "
                          "at {}",
                          raw.triangles.size(), mesh.first_degenerate_where));
  return mesh;
}

}  // namespace

TriangleMesh read_mesh(const fs::path& file, const MeshReadOptions& options) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext != ".stl" && ext != ".obj" && ext != ".off")
    throw FormatError(file, "", fmt::format("unknown mesh format '{}' (expected .stl, .obj or .off)", ext));
  const std::string bytes = read_all(file);
  const RawMesh raw = ext == ".stl"   ? parse_stl(file, bytes)
                      : ext == ".obj" ? parse_obj(file, bytes)
                                      : parse_off(file, bytes);
  if (raw.vertices.size() > static_cast<std::size_t>(INT32_MAX))
    throw FormatError(file, "", "more than 2^31 vertices");
  return finish(file, raw, options);
}

}  // namespace basalt::io
