#include "restart_support.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/parallel/balance.hpp"

namespace basalt::run {

namespace fs = std::filesystem;
using solver::InputError;

fs::path resolve_restart(const fs::path& p, bool print) {
  if (fs::is_directory(p)) {
    std::vector<fs::path> skipped;
    const auto latest = io::latest_complete_checkpoint(p, &skipped);
    std::string names;
    for (const auto& s : skipped) names += (names.empty() ? "" : ", ") + s.filename().string();
    if (latest.empty())
      throw InputError(fmt::format("--restart {}: no complete checkpoint (ckpt_<step>.h5) in this folder{}",
                                   p.string(),
                                   skipped.empty() ? std::string()
                                                   : fmt::format(" ({} not complete: cut off, or being "
                                                                 "written when the run stopped)",
                                                                 names)));
    if (print) {
      if (!skipped.empty())
        fmt::print(
            stderr,
            "basalt-run: warning: --restart {}: {} not complete (cut off, or being written when the run "
            "stopped); continuing from the newest complete checkpoint, {}\n",
            p.string(), names, latest.string());
      else
        fmt::print("restart: {} is the newest complete checkpoint in {}\n", latest.filename().string(),
                   p.string());
    }
    return latest;
  }
  if (!fs::exists(p)) throw InputError(fmt::format("--restart {}: no such file or folder", p.string()));
  return p;
}

namespace {
std::string vec_text(const std::array<double, 3>& v) {
  return fmt::format("{:.17g},{:.17g},{:.17g}", v[0], v[1], v[2]);
}

const std::string& attribute(const io::CheckpointHeader& c, const fs::path& file, const std::string& key) {
  const auto it = c.run.geometry.attributes.find(key);
  if (it == c.run.geometry.attributes.end())
    throw InputError(
        fmt::format("{}: attribute '{}' is missing: a restart needs the decomposition the run used "
                    "(checkpoints written by basalt-run carry it)",
                    file.string(), key));
  return it->second;
}

double number(const io::CheckpointHeader& c, const fs::path& file, const std::string& key) {
  const auto& t = attribute(c, file, key);
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (end == t.c_str() || *end != '\0')
    throw InputError(fmt::format("{}: attribute '{}' = \"{}\" is not a number", file.string(), key, t));
  return v;
}

std::array<double, 3> vec(const io::CheckpointHeader& c, const fs::path& file, const std::string& key) {
  const auto& t = attribute(c, file, key);
  std::array<double, 3> v{};
  const char* s = t.c_str();
  for (int d = 0; d < 3; ++d) {
    char* end = nullptr;
    v[d] = std::strtod(s, &end);
    if (end == s || (d < 2 && *end != ',') || (d == 2 && *end != '\0'))
      throw InputError(
          fmt::format("{}: attribute '{}' = \"{}\" is not three numbers", file.string(), key, t));
    s = end + 1;
  }
  return v;
}
}  // namespace

std::map<std::string, std::string> restart_attributes(const solver::RestartLayout& l) {
  return {{"decomposition_box_min", vec_text(l.box_min)},
          {"decomposition_box_max", vec_text(l.box_max)},
          {"ghost_width", fmt::format("{:.17g}", l.ghost_width)},
          {"contact_cutoff", fmt::format("{:.17g}", l.contact_cutoff)},
          {"decomposition_cuts", solver::cuts_text(l.cuts[0], l.cuts[1], l.cuts[2])},
          {"frame_origin", vec_text(l.origin)}};
}

solver::RestartLayout restart_layout_of(const io::CheckpointHeader& c, const fs::path& file) {
  solver::RestartLayout l;
  l.box_min = vec(c, file, "decomposition_box_min");
  l.box_max = vec(c, file, "decomposition_box_max");
  l.ghost_width = number(c, file, "ghost_width");
  l.contact_cutoff = number(c, file, "contact_cutoff");
  // The cuts in force at the checkpoint (run.balance); an older checkpoint has the even grid's.
  if (const auto it = c.run.geometry.attributes.find("decomposition_cuts");
      it != c.run.geometry.attributes.end()) {
    const auto cuts = solver::parse_cuts(it->second);
    if (!cuts)
      throw InputError(
          fmt::format("{}: attribute 'decomposition_cuts' = \"{}\" is not three ';'-separated lists "
                      "of numbers",
                      file.string(), it->second));
    l.cuts = *cuts;
  }
  // run.precision = "mixed": the origin of the run's frame (box and cuts are relative to it); zero before.
  if (c.run.geometry.attributes.count("frame_origin")) l.origin = vec(c, file, "frame_origin");
  return l;
}

void check_same_scene(const io::CheckpointHeader& c, const fs::path& file, const solver::Scene& scene) {
  if (c.run.scene_text != scene.text)
    throw InputError(
        fmt::format("{}: this checkpoint was written by another scene ({} particles; its stored scene text "
                    "differs from {}): "
                    "restart it with the scene file that wrote it",
                    file.string(), c.particles, scene.file.string()));
}

void check_same_precision(const io::CheckpointHeader& c, const fs::path& file, const std::string& precision) {
  const auto it = c.run.geometry.attributes.find("precision");
  const std::string written = it == c.run.geometry.attributes.end() ? "double" : it->second;
  if (written != precision)
    throw InputError(fmt::format(
        "{}: this checkpoint was written by a run in {} precision; restarting it in {} is refused (the "
        "continuation would not be the run's): restart with --precision {} (or run.precision = \"{}\")",
        file.string(), written, precision, written, written));
}

std::optional<std::int64_t> truncate_fields(const fs::path& csv, std::int64_t step) {
  if (!fs::exists(csv)) return std::nullopt;
  std::optional<std::int64_t> last;
  std::ifstream in(csv);
  std::string line, kept;
  bool header = true;
  while (std::getline(in, line)) {
    if (header) {
      kept += line + "\n";
      header = false;
      continue;
    }
    if (line.empty()) continue;
    const long long s = std::strtoll(line.c_str(), nullptr, 10);
    if (s <= step) {
      kept += line + "\n";
      last = s;
    }
  }
  const fs::path tmp = csv.string() + ".partial";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << kept;
    if (!out.flush()) throw InputError(fmt::format("{}: cannot rewrite for the restart", tmp.string()));
  }
  fs::rename(tmp, csv);
  return last;
}

}  // namespace basalt::run
