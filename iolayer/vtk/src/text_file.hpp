#pragma once
// Small helpers for the VTK writers: atomic text files (temporary name, then rename) and XML escaping.
#include <filesystem>
#include <string>

#include "basalt/io/xml_escape.hpp"

namespace basalt::io::detail {

/// "<file>.partial": where a file is written before it is renamed to its final name.
std::filesystem::path partial_name(const std::filesystem::path& file);
/// Throws FormatError naming `file` when its folder does not exist.
void require_folder(const std::filesystem::path& file);
/// Renames `tmp` to `file`; throws FormatError naming `file` (and removes `tmp`) on failure.
void commit(const std::filesystem::path& tmp, const std::filesystem::path& file);
/// Writes `text` to `file` through a temporary name; the final name never holds a partial file.
void write_text_atomically(const std::filesystem::path& file, const std::string& text);
using io::xml_escape;  // basalt/io/xml_escape.hpp, shared with the XDMF writer

}  // namespace basalt::io::detail
