#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <fstream>
#include <system_error>

#include "basalt/io/vtk_frames.hpp"
#include "text_file.hpp"

namespace basalt::io {

namespace fs = std::filesystem;

namespace {

std::string xml_unescape(std::string s) {
  const std::pair<const char*, char> table[] = {
      {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&amp;", '&'}};
  for (const auto& [from, to] : table) {
    const std::string f = from;
    for (std::size_t pos = s.find(f); pos != std::string::npos; pos = s.find(f, pos + 1))
      s.replace(pos, f.size(), 1, to);
  }
  return s;
}

/// Value of attribute `name="..."` on `line`, or false.
bool attribute(const std::string& line, const std::string& name, std::string& value) {
  const std::string key = " " + name + "=\"";
  const auto start = line.find(key);
  if (start == std::string::npos) return false;
  const auto begin = start + key.size();
  const auto end = line.find('"', begin);
  if (end == std::string::npos) return false;
  value = xml_unescape(line.substr(begin, end - begin));
  return true;
}

}  // namespace

PvdSeries::PvdSeries(fs::path pvd, bool resume) : pvd_(std::move(pvd)) {
  std::error_code ec;
  if (!resume || !fs::exists(pvd_, ec)) return;
  std::ifstream in(pvd_);
  if (!in) throw FormatError(pvd_, "", "cannot open for reading");
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.find("<DataSet") == std::string::npos) continue;
    std::string time_text, file;
    double t = 0;
    if (!attribute(line, "timestep", time_text) || !attribute(line, "file", file))
      throw FormatError(pvd_, fmt::format("line {}", number), "DataSet without timestep and file attributes");
    const auto [ptr, err] = std::from_chars(time_text.data(), time_text.data() + time_text.size(), t);
    if (err != std::errc() || ptr != time_text.data() + time_text.size())
      throw FormatError(pvd_, fmt::format("line {}", number),
                        fmt::format("timestep \"{}\" is not a number", time_text));
    entries_.push_back({t, file});
  }
}

void PvdSeries::add(double time, const fs::path& file) {
  fs::path rel = file;
  if (file.is_absolute()) {
    const fs::path base = fs::absolute(pvd_).parent_path();
    rel = file.lexically_relative(base);
    if (rel.empty()) rel = file;
  }
  entries_.push_back({time, rel.generic_string()});
  rewrite();
}

void PvdSeries::truncate_after(double t) {
  std::erase_if(entries_, [t](const Entry& e) { return e.time > t; });
  rewrite();
}

void PvdSeries::truncate_before_or_at(double t) {
  std::erase_if(entries_, [t](const Entry& e) { return e.time >= t; });
  rewrite();
}

void PvdSeries::rewrite() const {
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n";
  for (const auto& e : entries_)
    xml += fmt::format("    <DataSet timestep=\"{:.17g}\" group=\"\" part=\"0\" file=\"{}\"/>\n", e.time,
                       detail::xml_escape(e.file));
  xml += "  </Collection>\n</VTKFile>\n";
  detail::write_text_atomically(pvd_, xml);
}

}  // namespace basalt::io
