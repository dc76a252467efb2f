#include "basalt/io/xdmf.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "basalt/io/xml_escape.hpp"
#include "h5_support.hpp"

namespace basalt::io {

namespace fs = std::filesystem;

namespace {

const char* kGridBegin = "<Grid Name=\"particles\"";
const char* kGridEnd = "</Grid>";
const char* kVerticesSchema = "basalt-xdmf-vertices";
constexpr std::int64_t kVerticesSchemaVersion = 1;

void write_atomically(const fs::path& file, const std::string& text) {
  const fs::path tmp = file.string() + ".partial";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw FormatError(file, "", fmt::format("cannot create: {}", std::strerror(errno)));
    out << text;
    out.close();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw FormatError(file, "", "write failed (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw FormatError(file, "", fmt::format("cannot rename into place: {}", ec.message()));
  }
}

/// `text` with every line prefixed by `spaces` spaces (the XML below is built at indentation 0).
std::string indent(const std::string& text, std::size_t spaces) {
  const std::string pad(spaces, ' ');
  std::string out;
  std::size_t at = 0;
  while (at < text.size()) {
    const auto eol = text.find('\n', at);
    const auto end = eol == std::string::npos ? text.size() : eol + 1;
    out += pad + text.substr(at, end - at);
    at = end;
  }
  return out;
}

/// `text` with its first line's indentation taken off every line (those spaces only).
std::string dedent(const std::string& text) {
  const std::size_t spaces = text.find_first_not_of(' ');
  if (spaces == 0 || spaces == std::string::npos) return text;
  std::string out;
  std::size_t at = 0;
  while (at < text.size()) {
    const auto eol = text.find('\n', at);
    const auto end = eol == std::string::npos ? text.size() : eol + 1;
    std::size_t skip = 0;
    while (skip < spaces && at + skip < end && text[at + skip] == ' ') ++skip;
    out += text.substr(at + skip, end - at - skip);
    at = end;
  }
  return out;
}

std::string data_item(const std::string& h5, const char* dataset, std::size_t n, int components,
                      const char* number_type, int precision) {
  const std::string dims = components == 1 ? fmt::format("{}", n) : fmt::format("{} {}", n, components);
  return fmt::format(
      "<DataItem Dimensions=\"{}\" NumberType=\"{}\" Precision=\"{}\" Format=\"HDF\">{}:{}</DataItem>\n",
      dims, number_type, precision, h5, dataset);
}

std::string attribute(const std::string& h5, const char* name, const char* dataset, std::size_t n,
                      int components, const char* number_type, int precision) {
  return fmt::format("<Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\">\n{}</Attribute>\n", name,
                     components == 3 ? "Vector" : "Scalar",
                     indent(data_item(h5, dataset, n, components, number_type, precision), 2));
}

/// N vertex cells, cell i on point i: its connectivity is the first N of the `capacity` indices of the
/// vertex file (a HyperSlab: start 0, stride 1, count N). Without an explicit connectivity ParaView's
/// Xdmf3 readers make no cells at all; with none to connect (N = 0) there is nothing to read.
std::string topology(std::size_t n, std::size_t capacity) {
  if (n == 0) return "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"0\" NodesPerElement=\"1\"/>\n";
  return fmt::format(
      "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{0}\" NodesPerElement=\"1\">\n"
      "  <DataItem ItemType=\"HyperSlab\" Dimensions=\"{0}\" NumberType=\"Int\" Precision=\"8\">\n"
      "    <DataItem Dimensions=\"3 1\" Format=\"XML\">0 1 {0}</DataItem>\n"
      "    <DataItem Dimensions=\"{1}\" NumberType=\"Int\" Precision=\"8\" "
      "Format=\"HDF\">{2}:/vertices</DataItem>\n"
      "  </DataItem>\n"
      "</Topology>\n",
      n, capacity, kXdmfVerticesFile);
}

/// A temporal collection of `grids`: the form in which all three of ParaView's XDMF readers see time
/// (the Xdmf3 readers ignore a lone grid's <Time>).
std::string temporal_collection(const char* name, const std::string& grids) {
  return fmt::format("<Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Temporal\">\n", name) +
         indent(grids, 2) + "</Grid>\n";
}

std::string document(const std::string& body) {
  return "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"3.0\">\n  "
         "<Domain>\n" +
         indent(body, 4) + "  </Domain>\n</Xdmf>\n";
}

/// The whole `ckpt_<step>.xmf` of one particle grid.
std::string checkpoint_document(const std::string& grid) {
  return document(temporal_collection("checkpoint", grid));
}

/// The step in a name ckpt_<digits>.xmf, or -1.
long long step_of(const std::string& name) {
  if (name.size() < 10 || name.rfind("ckpt_", 0) != 0 || name.substr(name.size() - 4) != ".xmf") return -1;
  const std::string digits = name.substr(5, name.size() - 9);
  if (digits.empty() ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return -1;
  return std::stoll(digits);
}

/// One particle grid read back from a `ckpt_<step>.xmf` (this version's or an older one's), at
/// indentation 0, split around its <Topology> element so that the topology can be written anew.
struct ParsedGrid {
  double time = 0;
  std::size_t n = 0;
  std::string before, after;  // the grid's lines before and after the topology's lines
  std::size_t topology_indent = 0;
};

/// Unsigned decimal value of the XML attribute `name="..."` in `s` at or after `from` and before `to`.
std::optional<std::size_t> count_attribute(const std::string& s, const std::string& name, std::size_t from,
                                           std::size_t to) {
  const std::string key = name + "=\"";
  const auto at = s.find(key, from);
  if (at == std::string::npos || at >= to) return std::nullopt;
  const char* digits = s.c_str() + at + key.size();
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(digits, &end, 10);
  if (end == digits || *end != '"' || errno != 0 || *digits == '-') return std::nullopt;
  return static_cast<std::size_t>(v);
}

/// The particle grid of an .xmf file's text, or nothing when the text is not one of ours (or is being
/// replaced).
std::optional<ParsedGrid> parse_grid(const std::string& s, std::string& grid) {
  const auto begin = s.find(kGridBegin);
  if (begin == std::string::npos) return std::nullopt;
  const auto end = s.find(kGridEnd, begin);
  if (end == std::string::npos) return std::nullopt;
  // From the start of the grid's line, so that dedent sees its indentation.
  const auto line = s.rfind('\n', begin);
  const std::size_t from = line == std::string::npos ? 0 : line + 1;
  grid = dedent(s.substr(from, end + std::strlen(kGridEnd) - from) + "\n");

  ParsedGrid p;
  const auto time_at = grid.find("<Time Value=\"");
  const auto t = grid.find("<Topology");
  if (time_at == std::string::npos || t == std::string::npos) return std::nullopt;
  p.time = std::strtod(grid.c_str() + time_at + 13, nullptr);
  const auto tag_end = grid.find('>', t);
  if (tag_end == std::string::npos) return std::nullopt;
  const auto n = count_attribute(grid, "NumberOfElements", t, tag_end);
  if (!n) return std::nullopt;
  p.n = *n;
  std::size_t topo_end = tag_end + 1;  // a self-closing <Topology .../> (an older Basalt's: no connectivity)
  if (grid[tag_end - 1] != '/') {
    const auto close = grid.find("</Topology>", t);
    if (close == std::string::npos) return std::nullopt;
    topo_end = close + std::strlen("</Topology>");
  }
  const auto topo_line = grid.rfind('\n', t);
  const std::size_t line_begin = topo_line == std::string::npos ? 0 : topo_line + 1;
  const auto eol = grid.find('\n', topo_end);
  const std::size_t line_end = eol == std::string::npos ? grid.size() : eol + 1;
  p.topology_indent = t - line_begin;
  p.before = grid.substr(0, line_begin);
  p.after = grid.substr(line_end);
  return p;
}

std::string grid_with_topology(const ParsedGrid& p, std::size_t capacity) {
  return p.before + indent(topology(p.n, capacity), p.topology_indent) + p.after;
}

}  // namespace

std::size_t ensure_xdmf_vertices(const fs::path& dir, std::size_t n) {
  const fs::path file = dir / kXdmfVerticesFile;
  std::size_t have = 0;
  std::error_code ec;
  if (fs::exists(file, ec)) {
    try {
      const h5::Reader r(file);
      if (r.has_attribute("/", "schema") && r.attribute_is_string("/", "schema") &&
          r.string_attribute("/", "schema") == kVerticesSchema)
        have = r.rows<std::int64_t>("/vertices");
    } catch (const FormatError&) {
      have = 0;  // damaged or not ours: written anew below
    }
  }
  if (have >= n) return have;
  // Exactly n indices: the file is rewritten only when a checkpoint has more particles than any before.
  // Compressed (shuffle + deflate 1: 0..N-1 shrinks about 200-fold) and made one slab at a time, so the
  // writer holds one slab and the small compressed image, never N indices.
  h5::Writer w(file, file.string() + ".partial");
  try {
    w.compress(1);
  } catch (const FormatError&) {
    // This HDF5 has no deflate filter: the indices are written plain (8 bytes each).
  }
  w.attribute("/", "schema", kVerticesSchema);
  w.scalar_attribute<std::int64_t>("/", "schema_version", kVerticesSchemaVersion);
  w.int64_dataset_by_slabs("/vertices", n, [](std::size_t begin, std::span<std::int64_t> out) {
    std::iota(out.begin(), out.end(), static_cast<std::int64_t>(begin));
  });
  w.commit();
  return n;
}

void write_checkpoint_xdmf(const Checkpoint& c, const fs::path& h5) {
  const std::size_t n = c.size();
  const fs::path dir = h5.has_parent_path() ? h5.parent_path() : fs::path(".");
  const std::size_t capacity = n > 0 ? ensure_xdmf_vertices(dir, n) : 0;
  const std::string file = xml_escape(h5.filename().string());
  std::string body = fmt::format("<Time Value=\"{:.17g}\"/>\n", c.time);
  body += fmt::format("<Information Name=\"step\" Value=\"{}\"/>\n", c.step);
  body += topology(n, capacity);
  body += "<Geometry GeometryType=\"XYZ\">\n" +
          indent(data_item(file, "/particles/position", n, 3, "Float", 8), 2) + "</Geometry>\n";
  body += attribute(file, "velocity", "/particles/velocity", n, 3, "Float", 8);
  body += attribute(file, "radius", "/particles/radius", n, 1, "Float", 8);
  body += attribute(file, "mass", "/particles/mass", n, 1, "Float", 8);
  body += attribute(file, "id", "/particles/id", n, 1, "Int", 8);
  body += attribute(file, "tag", "/particles/tag", n, 1, "Int", 4);
  const std::string grid =
      std::string(kGridBegin) + " GridType=\"Uniform\">\n" + indent(body, 2) + kGridEnd + "\n";
  fs::path xmf = h5;
  xmf.replace_extension(".xmf");
  write_atomically(xmf, checkpoint_document(grid));
}

void write_checkpoint_series_xdmf(const fs::path& dir, std::int64_t up_to_step) {
  const fs::path series = dir / "ckpt_series.xmf";
  struct Entry {
    long long step;
    fs::path xmf;
    std::string grid;  // as read
    ParsedGrid parsed;
  };
  std::vector<Entry> entries;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    const long long step = step_of(name);
    if (step < 0 || step > up_to_step) continue;
    fs::path h5 = e.path();
    h5.replace_extension(".h5");
    if (!fs::exists(h5, ec)) continue;
    std::ifstream in(e.path(), std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    Entry entry{step, e.path(), {}, {}};
    auto parsed = parse_grid(text.str(), entry.grid);
    if (!parsed) continue;  // not one of ours (or being replaced): left out
    entry.parsed = std::move(*parsed);
    entries.push_back(std::move(entry));
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return std::tie(a.parsed.time, a.step) < std::tie(b.parsed.time, b.step);
  });
  // Every grid reads the vertex file as it is now: long enough for the largest, and each grid stating
  // its present length. A checkpoint's own .xmf that said otherwise (an older Basalt's, without
  // connectivity; a missing or shorter vertex file) is rewritten with the grid the series lists.
  std::size_t most = 0;
  for (const auto& e : entries) most = std::max(most, e.parsed.n);
  const std::size_t capacity = most > 0 ? ensure_xdmf_vertices(dir, most) : 0;
  std::string grids;
  for (const auto& e : entries) {
    const std::string grid = grid_with_topology(e.parsed, capacity);
    if (grid != e.grid) write_atomically(e.xmf, checkpoint_document(grid));
    grids += grid;
  }
  write_atomically(series, document(temporal_collection("checkpoints", grids)));
}

}  // namespace basalt::io
