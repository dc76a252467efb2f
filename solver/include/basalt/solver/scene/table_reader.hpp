#pragma once
// Reads one TOML table of a scene and names the file, line and key in every error:
// a missing key, a wrong type, an impossible value, and (finish()) any key nobody asked for,
// which is how misspellings are caught.
#include <toml++/toml.h>

#include <array>
#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "basalt/solver/core/errors.hpp"

namespace basalt::solver {

class TableReader {
 public:
  TableReader(const toml::table& table, std::string file, std::string path)
      : table_(table), file_(std::move(file)), path_(std::move(path)) {}

  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }
  bool has(const std::string& key) const { return table_.contains(key); }

  /// "<file>:<line>: <path>.<key>: <what>"
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
  [[noreturn]] void fail_here(const std::string& what) const;

  double number(const std::string& key);
  double number_or(const std::string& key, double fallback);
  std::int64_t integer(const std::string& key);
  std::int64_t integer_or(const std::string& key, std::int64_t fallback);
  bool boolean_or(const std::string& key, bool fallback);
  std::string string(const std::string& key);
  std::string string_or(const std::string& key, const std::string& fallback);
  /// One of `allowed`; the error lists them.
  std::string choice_or(const std::string& key, const std::vector<std::string>& allowed,
                        const std::string& fallback);
  std::array<double, 3> vec3(const std::string& key);
  std::optional<std::array<double, 3>> vec3_opt(const std::string& key);
  /// A number or an array of numbers, as a list (finite values only).
  std::vector<double> number_list(const std::string& key);
  std::vector<std::int64_t> integers_or(const std::string& key, std::vector<std::int64_t> fallback);
  std::vector<std::string> strings_or(const std::string& key, std::vector<std::string> fallback);
  /// A sub-table (must be a table); marks the key used.
  const toml::table* subtable(const std::string& key);
  /// An array of tables (may be absent).
  const toml::array* table_array(const std::string& key);

  double positive(const std::string& key);      ///< > 0 and finite
  double non_negative(const std::string& key);  ///< >= 0 and finite
  double non_negative_or(const std::string& key, double fallback);

  /// Throws naming the first key that was never read (unknown or misspelled).
  void finish() const;

  int line_of(const std::string& key) const;

 private:
  const toml::node& node(const std::string& key);

  const toml::table& table_;
  std::string file_;
  std::string path_;
  std::set<std::string> used_;
};

}  // namespace basalt::solver
