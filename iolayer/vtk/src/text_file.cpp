#include "text_file.hpp"

#include <fmt/format.h>

#include <fstream>
#include <system_error>

#include "basalt/io/geometry.hpp"
#include "basalt/io/xml_escape.hpp"

namespace basalt::io::detail {

namespace fs = std::filesystem;

fs::path partial_name(const fs::path& file) { return fs::path(file.string() + ".partial"); }

void require_folder(const fs::path& file) {
  const fs::path dir = file.parent_path().empty() ? fs::path(".") : file.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw FormatError(file, "", fmt::format("folder {} does not exist", dir.string()));
}

void commit(const fs::path& tmp, const fs::path& file) {
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw FormatError(file, "", "cannot rename the finished file into place: " + ec.message());
  }
}

void write_text_atomically(const fs::path& file, const std::string& text) {
  require_folder(file);
  const fs::path tmp = partial_name(file);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw FormatError(file, "", "cannot open for writing");
    out << text;
    out.flush();
    if (!out) {
      out.close();
      std::error_code ec;
      fs::remove(tmp, ec);
      throw FormatError(file, "", "write failed (disk full?)");
    }
  }
  commit(tmp, file);
}

}  // namespace basalt::io::detail
