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

InterruptStopsRun::InterruptStopsRun() {
  stop_signal = 0;
  if (sigaction(SIGINT, nullptr, &former_) != 0) return;
  if (!(former_.sa_flags & SA_SIGINFO) && (former_.sa_handler == SIG_IGN || former_.sa_handler == SIG_DFL))
    return;
  struct sigaction record {};
  record.sa_handler = record_stop_signal;
  sigemptyset(&record.sa_mask);
  installed_ = sigaction(SIGINT, &record, nullptr) == 0;
}

InterruptStopsRun::~InterruptStopsRun() { restore(); }

int InterruptStopsRun::restore() {
  if (installed_) sigaction(SIGINT, &former_, nullptr);
  installed_ = false;
  const int sig = stop_signal;
  stop_signal = 0;
  return sig;
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
