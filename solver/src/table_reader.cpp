#include "basalt/solver/scene/table_reader.hpp"

#include <fmt/format.h>

namespace basalt::solver {

int TableReader::line_of(const std::string& key) const {
  if (const auto* n = table_.get(key)) return static_cast<int>(n->source().begin.line);
  return static_cast<int>(table_.source().begin.line);
}

void TableReader::fail(const std::string& key, const std::string& what) const {
  throw InputError(
      fmt::format("{}:{}: {}{}{}: {}", file_, line_of(key), path_, path_.empty() ? "" : ".", key, what));
}

void TableReader::fail_here(const std::string& what) const {
  throw InputError(fmt::format("{}:{}: {}: {}", file_, table_.source().begin.line, path_, what));
}

const toml::node& TableReader::node(const std::string& key) {
  const auto* n = table_.get(key);
  if (!n) fail(key, "missing (required)");
  used_.insert(key);
  return *n;
}

double TableReader::number(const std::string& key) {
  const auto& n = node(key);
  if (auto v = n.value_exact<double>()) return *v;
  if (auto i = n.value_exact<std::int64_t>()) return static_cast<double>(*i);
  fail(key, "must be a number");
}

double TableReader::number_or(const std::string& key, double fallback) {
  return has(key) ? number(key) : fallback;
}

std::int64_t TableReader::integer(const std::string& key) {
  const auto& n = node(key);
  if (auto i = n.value_exact<std::int64_t>()) return *i;
  fail(key, "must be an integer");
}

std::int64_t TableReader::integer_or(const std::string& key, std::int64_t fallback) {
  return has(key) ? integer(key) : fallback;
}

bool TableReader::boolean_or(const std::string& key, bool fallback) {
  if (!has(key)) return fallback;
  const auto& n = node(key);
  if (auto b = n.value_exact<bool>()) return *b;
  fail(key, "must be true or false");
}

std::string TableReader::string(const std::string& key) {
  const auto& n = node(key);
  if (auto s = n.value_exact<std::string>()) return *s;
  fail(key, "must be a string");
}

std::string TableReader::string_or(const std::string& key, const std::string& fallback) {
  return has(key) ? string(key) : fallback;
}

std::string TableReader::choice_or(const std::string& key, const std::vector<std::string>& allowed,
                                   const std::string& fallback) {
  if (!has(key) && fallback.empty())
    fail(key, fmt::format("missing (required): one of {}", fmt::join(allowed, ", ")));
  std::string s = string_or(key, fallback);
  for (const auto& a : allowed)
    if (a == s) return s;
  fail(key, fmt::format("\"{}\" is not one of: {}", s, fmt::join(allowed, ", ")));
}

std::array<double, 3> TableReader::vec3(const std::string& key) {
  const auto& n = node(key);
  const auto* arr = n.as_array();
  if (!arr || arr->size() != 3) fail(key, "must be an array of three numbers, e.g. [0.0, 0.0, 1.0]");
  std::array<double, 3> out{};
  for (std::size_t k = 0; k < 3; ++k) {
    const auto& e = (*arr)[k];
    if (auto v = e.value_exact<double>())
      out[k] = *v;
    else if (auto i = e.value_exact<std::int64_t>())
      out[k] = static_cast<double>(*i);
    else
      fail(key, "must be an array of three numbers");
    if (!std::isfinite(out[k])) fail(key, "components must be finite");
  }
  return out;
}

std::vector<double> TableReader::number_list(const std::string& key) {
  const auto& n = node(key);
  const auto value = [&](const toml::node& e) {
    double v = 0;
    if (auto d = e.value_exact<double>())
      v = *d;
    else if (auto i = e.value_exact<std::int64_t>())
      v = static_cast<double>(*i);
    else
      fail(key, "must be a number or an array of numbers");
    if (!std::isfinite(v)) fail(key, "must be finite");
    return v;
  };
  std::vector<double> out;
  if (const auto* arr = n.as_array())
    for (const auto& e : *arr) out.push_back(value(e));
  else
    out.push_back(value(n));
  return out;
}

std::optional<std::array<double, 3>> TableReader::vec3_opt(const std::string& key) {
  if (!has(key)) return std::nullopt;
  return vec3(key);
}

std::vector<std::int64_t> TableReader::integers_or(const std::string& key,
                                                   std::vector<std::int64_t> fallback) {
  if (!has(key)) return fallback;
  const auto& n = node(key);
  const auto* arr = n.as_array();
  if (!arr) fail(key, "must be an array of integers");
  std::vector<std::int64_t> out;
  for (const auto& e : *arr) {
    auto i = e.value_exact<std::int64_t>();
    if (!i) fail(key, "must be an array of integers");
    out.push_back(*i);
  }
  return out;
}

std::vector<std::string> TableReader::strings_or(const std::string& key, std::vector<std::string> fallback) {
  if (!has(key)) return fallback;
  const auto* arr = node(key).as_array();
  if (!arr) fail(key, "must be an array of strings");
  std::vector<std::string> out;
  for (const auto& e : *arr) {
    auto s = e.value_exact<std::string>();
    if (!s) fail(key, "must be an array of strings");
    out.push_back(*s);
  }
  return out;
}

const toml::table* TableReader::subtable(const std::string& key) {
  if (!has(key)) return nullptr;
  const auto& n = node(key);
  if (!n.is_table()) fail(key, "must be a table");
  return n.as_table();
}

const toml::array* TableReader::table_array(const std::string& key) {
  if (!has(key)) return nullptr;
  const auto& n = node(key);
  const auto* arr = n.as_array();
  if (!arr || !arr->is_array_of_tables()) fail(key, fmt::format("must be an array of tables ([[{}]])", key));
  return arr;
}

double TableReader::positive(const std::string& key) {
  double v = number(key);
  if (!std::isfinite(v)) fail(key, fmt::format("must be a finite number > 0, got {}", v));
  if (!(v > 0)) fail(key, fmt::format("must be > 0, got {}", v));
  return v;
}

double TableReader::non_negative(const std::string& key) {
  double v = number(key);
  if (!std::isfinite(v)) fail(key, fmt::format("must be a finite number >= 0, got {}", v));
  if (!(v >= 0)) fail(key, fmt::format("must be >= 0, got {}", v));
  return v;
}

double TableReader::non_negative_or(const std::string& key, double fallback) {
  return has(key) ? non_negative(key) : fallback;
}

void TableReader::finish() const {
  for (const auto& [k, v] : table_) {
    std::string key(k.str());
    if (!used_.count(key))
      throw InputError(fmt::format("{}:{}: {}{}{}: unknown key (misspelled?)", file_, v.source().begin.line,
                                   path_, path_.empty() ? "" : ".", key));
  }
}

}  // namespace basalt::solver
