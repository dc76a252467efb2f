// ESyS-Particle's text geometry, "LSMGeometry 1.2" (as written by GenGeo):
//   LSMGeometry 1.2
//   BoundingBox xmin ymin zmin xmax ymax zmax
//   PeriodicBoundaries px py pz
//   Dimension 3D
//   BeginParticles
//   Simple
//   <count>
//   x y z radius id tag            (count lines)
//   EndParticles
//   BeginConnect
//   <count>
//   id1 id2 bondtag                (count lines)
//   EndConnect
// Every error names the file and line number.
#include <fmt/format.h>
#include <fmt/os.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string_view>
#include <type_traits>
#include <unordered_map>

#include "basalt/io/geometry.hpp"
#include "geometry_order.hpp"

namespace basalt::io {

namespace fs = std::filesystem;

namespace {

class LineReader {
 public:
  explicit LineReader(const fs::path& file) : file_(file) {
    std::error_code ec;
    if (!fs::exists(file, ec)) throw FormatError(file, "", "no such file");
    if (fs::is_directory(file, ec)) throw FormatError(file, "", "is a folder, not a file");
    in_.open(file);
    if (!in_) throw FormatError(file, "", "cannot open for reading");
  }

  /// Next non-empty line split into fields; throws at end of file, naming what was expected.
  std::vector<std::string_view> next(const char* expected) {
    while (std::getline(in_, line_)) {
      ++line_no_;
      if (!line_.empty() && line_.back() == '\r') line_.pop_back();
      split();
      if (!fields_.empty()) return fields_;
    }
    throw FormatError(file_, fmt::format("line {}", line_no_ + 1),
                      fmt::format("unexpected end of file, expected {}", expected));
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw FormatError(file_, fmt::format("line {}", line_no_), what);
  }

  void expect_keyword(const char* kw, std::size_t nargs) {
    auto f = next(kw);
    if (f[0] != kw) fail(fmt::format("expected '{}', found '{}'", kw, line_));
    if (f.size() != nargs + 1) fail(fmt::format("'{}' takes {} values, found {}", kw, nargs, f.size() - 1));
  }

  template <class T>
  T number(std::string_view s, const char* what) const {
    T v{};
    const char* end = s.data() + s.size();
    auto [p, ec] = std::from_chars(s.data(), end, v);
    if constexpr (std::is_integral_v<T>)
      if (ec == std::errc::result_out_of_range && p == end)
        fail(fmt::format("{} '{}' is out of range: it must be a whole number from {} to {}", what, s,
                         std::numeric_limits<T>::min(), std::numeric_limits<T>::max()));
    if (ec != std::errc() || p != end) fail(fmt::format("{} '{}' is not a valid number", what, s));
    return v;
  }

  /// True when only blank lines remain; otherwise the next non-blank line becomes fields().
  bool eof_after_whitespace() {
    while (std::getline(in_, line_)) {
      ++line_no_;
      if (!line_.empty() && line_.back() == '\r') line_.pop_back();
      split();
      if (!fields_.empty()) return false;
    }
    return true;
  }

  const std::vector<std::string_view>& fields() const { return fields_; }
  std::size_t line() const { return line_no_; }

 private:
  void split() {
    fields_.clear();
    std::size_t i = 0;
    while (i < line_.size()) {
      while (i < line_.size() && (line_[i] == ' ' || line_[i] == '\t')) ++i;
      std::size_t j = i;
      while (j < line_.size() && line_[j] != ' ' && line_[j] != '\t') ++j;
      if (j > i) fields_.emplace_back(line_.data() + i, j - i);
      i = j;
    }
  }

  fs::path file_;
  std::ifstream in_;
  std::string line_;
  std::vector<std::string_view> fields_;
  std::size_t line_no_ = 0;
};

}  // namespace

Geometry read_geo(const fs::path& file) {
  LineReader r(file);
  Geometry g;
  auto head = r.next("LSMGeometry header");
  if (head[0] != "LSMGeometry") r.fail("not an ESyS-Particle geometry: first line must be 'LSMGeometry 1.2'");
  if (head.size() < 2 || (head[1] != "1.2" && head[1] != "1.1"))
    r.fail(fmt::format("unsupported LSMGeometry version '{}' (Basalt reads 1.1 and 1.2)",
                       head.size() < 2 ? "" : std::string(head[1])));

  r.expect_keyword("BoundingBox", 6);
  for (int k = 0; k < 3; ++k) {
    g.box_min[k] = r.number<double>(r.fields()[1 + k], "BoundingBox value");
    g.box_max[k] = r.number<double>(r.fields()[4 + k], "BoundingBox value");
  }
  r.expect_keyword("PeriodicBoundaries", 3);
  for (int k = 0; k < 3; ++k)
    g.periodic[k] = r.number<int>(r.fields()[1 + k], "PeriodicBoundaries flag") != 0;
  r.expect_keyword("Dimension", 1);
  if (r.fields()[1] != "3D") r.fail("only 'Dimension 3D' geometries are supported");
  r.expect_keyword("BeginParticles", 0);
  r.expect_keyword("Simple", 0);

  auto count_line = r.next("particle count");
  if (count_line.size() != 1) r.fail("expected the particle count alone on the line");
  const auto n = r.number<long long>(count_line[0], "particle count");
  if (n < 0) r.fail("particle count is negative");
  // The count comes from the file: reserve no more than a sane amount up front.
  const auto expect = static_cast<std::size_t>(std::min<long long>(n, 1 << 24));
  g.id.reserve(expect);
  g.position.reserve(expect);
  g.radius.reserve(expect);
  g.tag.reserve(expect);
  std::unordered_map<std::int64_t, std::size_t> line_of_id;  // id -> line, to name both lines of a duplicate
  line_of_id.reserve(expect * 2);
  for (long long i = 0; i < n; ++i) {
    auto f = r.next("a particle line 'x y z radius id tag'");
    if (f[0] == "EndParticles")
      r.fail(fmt::format("particle count says {}, but only {} particles follow", n, i));
    if (f.size() != 6)
      r.fail(fmt::format("particle line needs 6 fields 'x y z radius id tag', found {}", f.size()));
    Vec3 p{r.number<double>(f[0], "x"), r.number<double>(f[1], "y"), r.number<double>(f[2], "z")};
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      r.fail("position must be finite");
    double rad = r.number<double>(f[3], "radius");
    if (!(rad > 0) || !std::isfinite(rad)) r.fail(fmt::format("radius must be finite and > 0, got {}", f[3]));
    const auto pid = r.number<std::int64_t>(f[4], "id");
    if (auto [it, fresh] = line_of_id.emplace(pid, r.line()); !fresh)
      r.fail(fmt::format("duplicate particle id {} (first on line {})", pid, it->second));
    g.add_particle(pid, p, rad, r.number<std::int32_t>(f[5], "tag"));
  }
  auto end_p = r.next("EndParticles");
  if (end_p[0] != "EndParticles")
    r.fail(fmt::format("expected 'EndParticles' after {} particles (is the particle count too small?)", n));

  // Bonds are optional in files written without connections.
  g.attributes["source_format"] = "LSMGeometry 1.2";
  g.attributes["source_file"] = file.filename().string();
  if (r.eof_after_whitespace()) {
    g.sort_by_id();
    g.validate(file);
    return g;
  }
  auto f = r.fields();
  if (f[0] != "BeginConnect") r.fail("expected 'BeginConnect'");
  auto bc = r.next("bond count");
  if (bc.size() != 1) r.fail("expected the bond count alone on the line");
  const auto nb = r.number<long long>(bc[0], "bond count");
  if (nb < 0) r.fail("bond count is negative");
  g.bonds.reserve(static_cast<std::size_t>(std::min<long long>(nb, 1 << 24)));
  for (long long k = 0; k < nb; ++k) {
    auto b = r.next("a bond line 'id1 id2 tag'");
    if (b[0] == "EndConnect") r.fail(fmt::format("bond count says {}, but only {} bonds follow", nb, k));
    if (b.size() != 3) r.fail(fmt::format("bond line needs 3 fields 'id1 id2 tag', found {}", b.size()));
    auto a = r.number<std::int64_t>(b[0], "bond id1");
    auto c = r.number<std::int64_t>(b[1], "bond id2");
    for (auto e : {a, c})
      if (!line_of_id.count(e)) r.fail(fmt::format("bond refers to particle id {}, which does not exist", e));
    if (a == c) r.fail(fmt::format("bond joins particle {} to itself", a));
    g.add_bond(a, c, r.number<std::int32_t>(b[2], "bond tag"));
  }
  auto ec = r.next("EndConnect");
  if (ec[0] != "EndConnect")
    r.fail(fmt::format("expected 'EndConnect' after {} bonds (is the bond count too small?)", nb));
  if (!r.eof_after_whitespace()) r.fail("unexpected text after 'EndConnect'");

  g.sort_by_id();
  g.validate(file);
  return g;
}

void write_geo(const Geometry& unordered, const fs::path& file) {
  unordered.validate(file);
  Geometry storage;
  const Geometry& g = in_file_order(unordered, storage);
  const fs::path tmp = file.string() + ".tmp";
  const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
  std::error_code exists_ec;
  if (!fs::exists(folder, exists_ec))
    throw FormatError(file, "", fmt::format("cannot create: folder '{}' does not exist", folder.string()));
  if (!fs::is_directory(folder, exists_ec))
    throw FormatError(file, "", fmt::format("cannot create: '{}' is not a folder", folder.string()));
  {
    std::FILE* out = std::fopen(tmp.c_str(), "w");
    if (!out)
      throw FormatError(file, "", fmt::format("cannot create '{}': {}", tmp.string(), std::strerror(errno)));
    auto w = [&](std::string_view s) { return std::fwrite(s.data(), 1, s.size(), out) == s.size(); };
    bool ok = true;
    ok &= w("LSMGeometry 1.2\n");
    ok &= w(fmt::format("BoundingBox {} {} {} {} {} {}\n", g.box_min[0], g.box_min[1], g.box_min[2],
                        g.box_max[0], g.box_max[1], g.box_max[2]));
    ok &= w(fmt::format("PeriodicBoundaries {} {} {}\n", int(g.periodic[0]), int(g.periodic[1]),
                        int(g.periodic[2])));
    ok &= w("Dimension 3D\nBeginParticles\nSimple\n");
    ok &= w(fmt::format("{}\n", g.size()));
    fmt::memory_buffer buf;
    for (std::size_t i = 0; i < g.size() && ok; ++i) {
      buf.clear();
      fmt::format_to(std::back_inserter(buf), "{} {} {} {} {} {}\n", g.position[i][0], g.position[i][1],
                     g.position[i][2], g.radius[i], g.id[i], g.tag[i]);
      ok &= w(std::string_view(buf.data(), buf.size()));
    }
    ok &= w(fmt::format("EndParticles\nBeginConnect\n{}\n", g.bonds.size()));
    for (std::size_t k = 0; k < g.bonds.size() && ok; ++k)
      ok &= w(fmt::format("{} {} {}\n", g.bonds[k].a, g.bonds[k].b, g.bonds[k].tag));
    ok &= w("EndConnect\n");
    ok &= std::fflush(out) == 0;
    ok &= std::fclose(out) == 0;
    if (!ok) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw FormatError(file, "", "write failed (disk full or file-size limit?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) throw FormatError(file, "", "cannot rename temporary file into place: " + ec.message());
}

}  // namespace basalt::io
