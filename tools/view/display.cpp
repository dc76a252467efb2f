#include "display.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace basalt::view {

namespace {
bool set(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0';
}
}  // namespace

void ensure_display(int argc, char** argv) {
  if (set("DISPLAY") || set("BASALT_VIEW_NO_XVFB")) return;
  if (set("BASALT_VIEW_UNDER_XVFB"))
    throw std::runtime_error(
        "started under xvfb-run but still no DISPLAY: the virtual X server did not start");
  std::string self = "/proc/self/exe";
  std::vector<char> buf(4096);
  const ssize_t n = ::readlink("/proc/self/exe", buf.data(), buf.size() - 1);
  if (n > 0) self.assign(buf.data(), static_cast<std::size_t>(n));
  ::setenv("BASALT_VIEW_UNDER_XVFB", "1", 1);
  std::vector<std::string> args = {"xvfb-run", "-a", "-s", "-screen 0 1920x1200x24 -nolisten tcp", self};
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  std::vector<char*> cargs;
  for (auto& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  ::execvp("xvfb-run", cargs.data());
  throw std::runtime_error(
      fmt::format("no X display (DISPLAY is unset) and xvfb-run cannot be started ({}): install it with "
                  "`apt-get install xvfb xauth`, or set DISPLAY",
                  std::strerror(errno)));
}

}  // namespace basalt::view
