#pragma once
// What the whole-file checkpoint reader (h5_checkpoint.cpp) and the row-range one
// (h5_checkpoint_rows.cpp) share of schema "basalt-checkpoint" (docs/formats.md).
#include <fmt/format.h>

#include <string>
#include <string_view>
#include <vector>

#include "basalt/io/checkpoint.hpp"
#include "h5_geometry_layout.hpp"
#include "h5_support.hpp"

namespace basalt::io::h5 {

inline constexpr const char* kCheckpointSchema = "basalt-checkpoint";
inline constexpr int kCheckpointVersion = 1;
// Root attributes of this schema besides the geometry's; "complete" is written last.
inline constexpr std::string_view kRunAttributes[] = {
    "step", "time", "dt", "scene_text", "rebuild_step", "rebuild_pending", "complete"};

inline std::string root_attribute(const std::string& name) {
  return fmt::format("attribute '{}' of /", name);
}

/// Checks the completion mark: present and equal to 1.
void check_complete(const Reader& r);
/// The walls (/walls/<name>, placed by their attribute 'index'), checked for shape.
std::vector<WallState> read_walls(const Reader& r);
/// The attribute 'width' of /contacts, checked to be in [1, 64].
std::size_t contact_width(const Reader& r);

}  // namespace basalt::io::h5
