#include "basalt/io/xdmf.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "basalt/io/xml_escape.hpp"

namespace basalt::io {

namespace fs = std::filesystem;

namespace {

const char* kGridBegin = "<Grid Name=\"particles\"";
const char* kGridEnd = "</Grid>";

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

std::string data_item(const std::string& h5, const char* dataset, std::size_t n, int components,
                      const char* number_type, int precision) {
  const std::string dims = components == 1 ? fmt::format("{}", n) : fmt::format("{} {}", n, components);
  return fmt::format(
      "        <DataItem Dimensions=\"{}\" NumberType=\"{}\" Precision=\"{}\" "
      "Format=\"HDF\">{}:{}</DataItem>\n",
      dims, number_type, precision, h5, dataset);
}

std::string attribute(const std::string& h5, const char* name, const char* dataset, std::size_t n,
                      int components, const char* number_type, int precision) {
  return fmt::format(
      "      <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\">\n{}      </Attribute>\n", name,
      components == 3 ? "Vector" : "Scalar", data_item(h5, dataset, n, components, number_type, precision));
}

std::string document(const std::string& body) {
  return "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"3.0\">\n  "
         "<Domain>\n" +
         body + "  </Domain>\n</Xdmf>\n";
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

}  // namespace

void write_checkpoint_xdmf(const Checkpoint& c, const fs::path& h5) {
  const std::size_t n = c.size();
  const std::string file = xml_escape(h5.filename().string());
  std::string grid = fmt::format("    {} GridType=\"Uniform\">\n", kGridBegin);
  grid += fmt::format("      <Time Value=\"{:.17g}\"/>\n", c.time);
  grid += fmt::format("      <Information Name=\"step\" Value=\"{}\"/>\n", c.step);
  grid += fmt::format(
      "      <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" NodesPerElement=\"1\"/>\n", n);
  grid += "      <Geometry GeometryType=\"XYZ\">\n" +
          data_item(file, "/particles/position", n, 3, "Float", 8) + "      </Geometry>\n";
  grid += attribute(file, "velocity", "/particles/velocity", n, 3, "Float", 8);
  grid += attribute(file, "radius", "/particles/radius", n, 1, "Float", 8);
  grid += attribute(file, "mass", "/particles/mass", n, 1, "Float", 8);
  grid += attribute(file, "id", "/particles/id", n, 1, "Int", 8);
  grid += attribute(file, "tag", "/particles/tag", n, 1, "Int", 4);
  grid += fmt::format("    {}\n", kGridEnd);
  fs::path xmf = h5;
  xmf.replace_extension(".xmf");
  write_atomically(xmf, document(grid));
}

void write_checkpoint_series_xdmf(const fs::path& dir, std::int64_t up_to_step) {
  const fs::path series = dir / "ckpt_series.xmf";
  struct Entry {
    double time;
    long long step;
    std::string grid;
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
    const std::string s = text.str();
    const auto begin = s.find(kGridBegin);
    const auto end = s.find(kGridEnd, begin == std::string::npos ? 0 : begin);
    const auto time_at = s.find("<Time Value=\"");
    if (begin == std::string::npos || end == std::string::npos || time_at == std::string::npos)
      continue;  // not one of ours (or being replaced): left out
    Entry entry;
    entry.step = step;
    entry.time = std::strtod(s.c_str() + time_at + 13, nullptr);
    // Back up to the start of the line, so the grid keeps its indentation.
    const auto line = s.rfind('\n', begin);
    entry.grid = "  " + s.substr(line + 1, end + std::strlen(kGridEnd) - line - 1);
    // Indent the grid's other lines by two more spaces, inside the collection.
    for (std::size_t at = entry.grid.find('\n'); at != std::string::npos; at = entry.grid.find('\n', at + 3))
      entry.grid.insert(at + 1, "  ");
    entries.push_back(std::move(entry));
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return std::tie(a.time, a.step) < std::tie(b.time, b.step);
  });
  std::string body = "    <Grid Name=\"checkpoints\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const auto& e : entries) body += e.grid + "\n";
  body += "    </Grid>\n";
  write_atomically(series, document(body));
}

}  // namespace basalt::io
