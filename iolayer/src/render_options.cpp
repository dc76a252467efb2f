#include "basalt/io/render_options.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <set>
#include <stdexcept>
#include <system_error>

namespace basalt::io {

double parse_number(const std::string& s, const std::string& what) {
  double v = 0;
  const char* begin = s.data();
  if (!s.empty() && s[0] == '+') ++begin;
  const auto [ptr, ec] = std::from_chars(begin, s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v))
    throw std::invalid_argument(fmt::format("{}: \"{}\" is not a number", what, s));
  return v;
}

ImageSize parse_size(const std::string& s, const std::string& option) {
  const auto x = s.find('x');
  const std::string form = fmt::format("{} \"{}\": expected WIDTHxHEIGHT, e.g. 1600x1200", option, s);
  if (x == std::string::npos) throw std::invalid_argument(form);
  ImageSize size;
  const auto w = std::from_chars(s.data(), s.data() + x, size.width);
  const auto h = std::from_chars(s.data() + x + 1, s.data() + s.size(), size.height);
  if (w.ec != std::errc() || w.ptr != s.data() + x || h.ec != std::errc() || h.ptr != s.data() + s.size())
    throw std::invalid_argument(form);
  if (size.width < 16 || size.height < 16 || size.width > 16384 || size.height > 16384)
    throw std::invalid_argument(
        fmt::format("{} \"{}\": each side must be between 16 and 16384 pixels", option, s));
  return size;
}

Range parse_range(const std::string& s, const std::string& option) {
  // The separator is the first ':' not at the start (so "-1:2" and "1e-3:5" parse).
  const auto colon = s.find(':', 1);
  if (colon == std::string::npos)
    throw std::invalid_argument(fmt::format("{} \"{}\": expected MIN:MAX, e.g. 0:0.1", option, s));
  Range r{parse_number(s.substr(0, colon), option + " min"),
          parse_number(s.substr(colon + 1), option + " max")};
  if (!(r.min < r.max))
    throw std::invalid_argument(fmt::format("{} \"{}\": MIN must be less than MAX", option, s));
  return r;
}

Cut parse_cut(const std::string& s, const std::string& option) {
  Cut c;
  if (s.empty() || (s[0] != 'x' && s[0] != 'y' && s[0] != 'z') || (s.size() > 1 && s[1] != ':'))
    throw std::invalid_argument(
        fmt::format("{} \"{}\": expected x, y or z, optionally :VALUE (e.g. z:7.5)", option, s));
  c.axis = s[0] - 'x';
  if (s.size() > 2) c.value = parse_number(s.substr(2), option + " value");
  if (s.size() == 2)
    throw std::invalid_argument(fmt::format("{} \"{}\": missing value after ':'", option, s));
  return c;
}

ViewDirection parse_view(const std::string& s, const std::string& option) {
  ViewDirection v;
  if (s == "iso") return v;
  if (s.size() != 2 || (s[0] != '+' && s[0] != '-') || (s[1] != 'x' && s[1] != 'y' && s[1] != 'z'))
    throw std::invalid_argument(fmt::format("{} \"{}\": expected +x, -x, +y, -y, +z, -z or iso", option, s));
  const int axis = s[1] - 'x';
  v.toward_camera = {0, 0, 0};
  v.toward_camera[static_cast<std::size_t>(axis)] = s[0] == '+' ? 1.0 : -1.0;
  v.up = axis == 2 ? std::array<double, 3>{0, 1, 0} : std::array<double, 3>{0, 0, 1};
  return v;
}

RenderSpec parse_render_spec(const std::string& text, const std::string& what) {
  RenderSpec spec;
  spec.text = text;
  std::set<std::string> seen;
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t comma = text.find(',', at);
    if (comma == std::string::npos) comma = text.size();
    const std::string item = text.substr(at, comma - at);
    at = comma + 1;
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw std::invalid_argument(
          fmt::format("{} \"{}\": \"{}\" is not KEY=VALUE (keys: color, cut, view, range, size; e.g. "
                      "\"color=velocity_z,cut=y\")",
                      what, text, item));
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    const std::string option = fmt::format("{} {}", what, key);
    if (!seen.insert(key).second)
      throw std::invalid_argument(fmt::format("{} \"{}\": key \"{}\" given twice", what, text, key));
    if (key == "color" || key == "colour") {
      if (value.empty()) throw std::invalid_argument(fmt::format("{}: empty field name", option));
      spec.color = value;
    } else if (key == "cut") {
      spec.cut = parse_cut(value, option);
    } else if (key == "view") {
      spec.view = parse_view(value, option);
    } else if (key == "range") {
      spec.range = parse_range(value, option);
    } else if (key == "size") {
      spec.size = parse_size(value, option);
    } else {
      throw std::invalid_argument(fmt::format(
          "{} \"{}\": unknown key \"{}\" (keys: color, cut, view, range, size)", what, text, key));
    }
  }
  return spec;
}

}  // namespace basalt::io
