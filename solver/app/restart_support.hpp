#pragma once
// basalt-run --restart: finding the checkpoint, checking it belongs to the scene, and what the
// restart needs besides particles (the decomposition's box, ghost width, contact cut-off), stored as
// checkpoint attributes.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "basalt/io/checkpoint.hpp"
#include "basalt/io/checkpoint_rows.hpp"
#include "basalt/solver/scene/scene.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::run {

/// A file is taken as is; a folder gives its latest complete checkpoint. Throws InputError naming the
/// path when there is none. With `print` (world rank 0), says which checkpoint of the folder is taken,
/// and warns naming the newer ones passed over as not complete.
std::filesystem::path resolve_restart(const std::filesystem::path& file_or_dir, bool print = false);

/// Checkpoint attributes that let a restart rebuild the same decomposition (exact decimal text).
std::map<std::string, std::string> restart_attributes(const solver::RestartLayout& layout);
/// Reads them back; throws InputError naming the file and the missing attribute.
solver::RestartLayout restart_layout_of(const io::CheckpointHeader& c, const std::filesystem::path& file);

/// Refuses (InputError naming both files) a checkpoint written by another scene.
void check_same_scene(const io::CheckpointHeader& c, const std::filesystem::path& file,
                      const solver::Scene& scene);

/// Refuses (InputError naming the file and both precisions) a restart in another precision than the
/// checkpoint's run (attribute "precision"; checkpoints without it were written in double).
void check_same_precision(const io::CheckpointHeader& c, const std::filesystem::path& file,
                          const std::string& precision);

/// Keeps the header and the rows with step <= `step` of an existing fields.csv (rewritten atomically),
/// so that the restarted run appends to one series without duplicate steps. Returns the step of the last
/// row kept (nullopt when the file does not exist or has no rows).
std::optional<std::int64_t> truncate_fields(const std::filesystem::path& csv, std::int64_t step);

}  // namespace basalt::run
