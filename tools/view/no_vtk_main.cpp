// basalt-view in a build without VTK (BASALT_WITH_VTK off): every command of basalt-view draws, converts or
// reads files through VTK, so this stand-in only says so, in one line, and names the way round: checkpoints
// and their XDMF descriptions (ckpt_series.xmf) open in ParaView as they are. --version and --help answer.
#include <fmt/format.h>

#include <cstdio>
#include <string_view>

#include "basalt/version.hpp"

namespace {

constexpr std::string_view kCommands[] = {"render", "movie", "convert", "plot", "info"};

void print_help() {
  fmt::print(
      "basalt-view: render Basalt checkpoints and geometries to PNG, convert them to VTK for ParaView, plot "
      "field series.\n"
      "This build has no VTK (BASALT_WITH_VTK=OFF: {}), and every command needs it: render, movie, convert, "
      "plot, info are refused.\n"
      "Open a run's ckpt_series.xmf (checkpoints, written by basalt-run) in ParaView instead, or build "
      "Basalt with libvtk9-dev installed.\n"
      "Usage: basalt-view [--help] [--version]\n",
      BASALT_WITHOUT_VTK_REASON);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    print_help();
    fmt::print(stderr, "basalt-view: error: a command is required (render, movie, convert, plot, info)\n");
    return 1;
  }
  const std::string_view first = argv[1];
  if (first == "--version") {
    fmt::print("{}\n", basalt::kVersion);
    return 0;
  }
  if (first == "-h" || first == "--help") {
    print_help();
    return 0;
  }
  bool known = false;
  for (const auto c : kCommands) known = known || first == c;
  if (!known) {
    fmt::print(stderr,
               "basalt-view: error: unknown command \"{}\" (commands: render, movie, convert, plot, info)\n",
               first);
    return 1;
  }
  fmt::print(
      stderr,
      "basalt-view: error: {} needs VTK, and this build has none (BASALT_WITH_VTK=OFF: {}); open the run's "
      "ckpt_series.xmf in ParaView instead\n",
      first, BASALT_WITHOUT_VTK_REASON);
  return 1;
}
