#include "options.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace basalt::view {

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
