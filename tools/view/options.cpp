#include "options.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace basalt::view {

double parse_number(const std::string& s, const std::string& what) {
  double v = 0;
  const char* begin = s.data();
  if (!s.empty() && s[0] == '+') ++begin;
  const auto [ptr, ec] = std::from_chars(begin, s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v))
    throw std::invalid_argument(fmt::format("{}: \"{}\" is not a number", what, s));
  return v;
}

ImageSize parse_size(const std::string& s) {
  const auto x = s.find('x');
  const std::string form = fmt::format("--size \"{}\": expected WIDTHxHEIGHT, e.g. 1600x1200", s);
  if (x == std::string::npos) throw std::invalid_argument(form);
  ImageSize size;
  const auto w = std::from_chars(s.data(), s.data() + x, size.width);
  const auto h = std::from_chars(s.data() + x + 1, s.data() + s.size(), size.height);
  if (w.ec != std::errc() || w.ptr != s.data() + x || h.ec != std::errc() || h.ptr != s.data() + s.size())
    throw std::invalid_argument(form);
  if (size.width < 16 || size.height < 16 || size.width > 16384 || size.height > 16384)
    throw std::invalid_argument(
        fmt::format("--size \"{}\": each side must be between 16 and 16384 pixels", s));
  return size;
}

Range parse_range(const std::string& s) {
  // The separator is the first ':' not at the start (so "-1:2" and "1e-3:5" parse).
  const auto colon = s.find(':', 1);
  if (colon == std::string::npos)
    throw std::invalid_argument(fmt::format("--range \"{}\": expected MIN:MAX, e.g. 0:0.1", s));
  Range r{parse_number(s.substr(0, colon), "--range min"), parse_number(s.substr(colon + 1), "--range max")};
  if (!(r.min < r.max))
    throw std::invalid_argument(fmt::format("--range \"{}\": MIN must be less than MAX", s));
  return r;
}

Cut parse_cut(const std::string& s) {
  Cut c;
  if (s.empty() || (s[0] != 'x' && s[0] != 'y' && s[0] != 'z') || (s.size() > 1 && s[1] != ':'))
    throw std::invalid_argument(
        fmt::format("--cut \"{}\": expected x, y or z, optionally :VALUE (e.g. z:7.5)", s));
  c.axis = s[0] - 'x';
  if (s.size() > 2) c.value = parse_number(s.substr(2), "--cut value");
  if (s.size() == 2) throw std::invalid_argument(fmt::format("--cut \"{}\": missing value after ':'", s));
  return c;
}

ViewDirection parse_view(const std::string& s) {
  ViewDirection v;
  if (s == "iso") return v;
  if (s.size() != 2 || (s[0] != '+' && s[0] != '-') || (s[1] != 'x' && s[1] != 'y' && s[1] != 'z'))
    throw std::invalid_argument(fmt::format("--view \"{}\": expected +x, -x, +y, -y, +z, -z or iso", s));
  const int axis = s[1] - 'x';
  v.toward_camera = {0, 0, 0};
  v.toward_camera[static_cast<std::size_t>(axis)] = s[0] == '+' ? 1.0 : -1.0;
  v.up = axis == 2 ? std::array<double, 3>{0, 1, 0} : std::array<double, 3>{0, 0, 1};
  return v;
}

void require_writable(const std::string& file) {
  namespace fs = std::filesystem;
  const fs::path p(file);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw std::invalid_argument(fmt::format("cannot write {}: folder {} does not exist", file, dir.string()));
  if (::access(dir.c_str(), W_OK) != 0)
    throw std::invalid_argument(
        fmt::format("cannot write {}: folder {} is not writable", file, dir.string()));
  if (fs::is_directory(p, ec))
    throw std::invalid_argument(fmt::format("cannot write {}: it is a folder", file));
}

}  // namespace basalt::view
