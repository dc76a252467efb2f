#include "display.hpp"

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

}  // namespace

void ensure_display() {
  if (set("DISPLAY") || set("BASALT_VIEW_NO_XVFB")) return;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(fmt::format("pipe: {}", std::strerror(errno)));
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(fmt::format("fork: {}", std::strerror(errno)));
  if (pid == 0) {
    // The server: dies with basalt-view, writes its display number to the pipe when ready.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    ::close(fds[0]);
    const int keep = ::dup(fds[1]);  // without O_CLOEXEC, so that Xvfb inherits it
    const int devnull = ::open("/dev/null", O_WRONLY);
    if (devnull >= 0) {
      ::dup2(devnull, STDOUT_FILENO);
      ::dup2(devnull, STDERR_FILENO);
    }
    const std::string fd = std::to_string(keep);
    ::execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1920x1200x24", "-nolisten", "tcp",
             static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(fds[1]);
  server = pid;
  std::atexit(stop_server);

  std::string number;
  pollfd p{fds[0], POLLIN, 0};
  while (number.empty() || number.back() != '\n') {
    const int ready = ::poll(&p, 1, 20000);
    char buf[32];
    const ssize_t n = ready > 0 ? ::read(fds[0], buf, sizeof buf) : -1;
    if (n <= 0) {
      ::close(fds[0]);
      if (ready > 0) {  // end of file: the server exited before giving a display number
        int status = 0;
        ::waitpid(pid, &status, 0);
        server = -1;
        if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
          throw std::runtime_error(
              "no X display (DISPLAY is unset) and Xvfb is not installed: `apt-get install xvfb`, or set "
              "DISPLAY");
      }
      stop_server();
      throw std::runtime_error(
          "no X display (DISPLAY is unset) and the virtual X server (Xvfb) did not start");
    }
    number.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  number.pop_back();
  ::setenv("DISPLAY", (":" + number).c_str(), 1);
}

}  // namespace basalt::view
