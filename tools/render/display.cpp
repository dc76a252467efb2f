#include "display.hpp"

#include <X11/Xlib.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

namespace basalt::view {

namespace {

pid_t server = -1;

bool set(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0';
}

void stop_server() {
  if (server <= 0) return;
  ::kill(server, SIGTERM);
  int status = 0;
  ::waitpid(server, &status, 0);
  server = -1;
}

/// Starts a server on display `number`; returns false when it exits at once (the display is taken:
/// its lock file exists). Throws when Xvfb is not installed or does not answer within 20 s.
bool start_server(int number) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(fmt::format("pipe: {}", std::strerror(errno)));
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(fmt::format("fork: {}", std::strerror(errno)));
  if (pid == 0) {
    // The server: dies with basalt-view, writes its display number to the pipe once it listens.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    ::close(fds[0]);
    const int keep = ::dup(fds[1]);  // without O_CLOEXEC, so that Xvfb inherits it
    const int devnull = ::open("/dev/null", O_WRONLY);
    if (devnull >= 0) {
      ::dup2(devnull, STDOUT_FILENO);
      ::dup2(devnull, STDERR_FILENO);
    }
    const std::string display = fmt::format(":{}", number), fd = std::to_string(keep);
    ::execlp("Xvfb", "Xvfb", display.c_str(), "-displayfd", fd.c_str(), "-screen", "0", "1920x1200x24",
             "-nolisten", "tcp", "-noreset", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(fds[1]);
  server = pid;
  static const bool registered = std::atexit(stop_server) == 0;
  (void)registered;

  std::string answer;
  pollfd p{fds[0], POLLIN, 0};
  while (answer.empty() || answer.back() != '\n') {
    const int ready = ::poll(&p, 1, 20000);
    char buf[32];
    const ssize_t n = ready > 0 ? ::read(fds[0], buf, sizeof buf) : -1;
    if (n > 0) {
      answer.append(buf, static_cast<std::size_t>(n));
      continue;
    }
    ::close(fds[0]);
    if (ready <= 0) {
      stop_server();
      throw std::runtime_error(
          "no X display (DISPLAY is unset) and the virtual X server (Xvfb) did not start");
    }
    // End of file: the server exited without listening.
    int status = 0;
    ::waitpid(pid, &status, 0);
    server = -1;
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
      throw std::runtime_error(
          "no X display (DISPLAY is unset) and Xvfb is not installed: `apt-get install xvfb`, or set "
          "DISPLAY");
    return false;
  }
  ::close(fds[0]);
  return true;
}

}  // namespace

void ensure_display() {
  if (set("DISPLAY") || set("BASALT_VIEW_NO_XVFB")) return;
  // Displays from :99 up, like xvfb-run: :0-:9 are probed by hwloc (inside MPI_Init), and a server
  // there that comes and goes makes other programs' MPI start-up fail. A taken display (another
  // server's lock file) makes Xvfb exit at once: try the next one.
  for (int number = 99; number < 99 + 400; ++number) {
    if (!start_server(number)) continue;
    const std::string display = fmt::format(":{}", number);
    // Kept open until exit: an X server resets when its last client leaves, and a client connecting
    // during that reset (VTK opens and closes connections) is refused.
    if (Display* d = XOpenDisplay(display.c_str())) {
      (void)d;
      ::setenv("DISPLAY", display.c_str(), 1);
      return;
    }
    stop_server();
  }
  throw std::runtime_error("no X display (DISPLAY is unset) and no virtual X server (Xvfb) could be started");
}

}  // namespace basalt::view
