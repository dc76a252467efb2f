#include "basalt/solver/core/stop_request.hpp"

namespace basalt::solver {

namespace {

void record_stop_signal(int sig) {
  if (stop_signal == sig) {
    // Asked twice: stop now, as the signal's default action would.
    std::signal(sig, SIG_DFL);
    std::raise(sig);
    return;
  }
  stop_signal = sig;
}

}  // namespace

void install_stop_handlers() {
  std::signal(SIGTERM, record_stop_signal);
  std::signal(SIGINT, record_stop_signal);
}

const char* signal_name(int sig) {
  switch (sig) {
    case SIGTERM:
      return "SIGTERM";
    case SIGINT:
      return "SIGINT";
    default:
      return "a signal";
  }
}

}  // namespace basalt::solver
