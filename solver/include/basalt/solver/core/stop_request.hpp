#pragma once
// A request to stop the run early (SIGTERM, SIGINT): the handler only records the signal; the run loop
// looks at it where the compute ranks already agree on output errors (every 32 steps and at output
// steps), so that all stop at the same step, hand over the field rows computed so far, let the I/O
// ranks finish what they hold, and exit non-zero with a message. A second signal of the same kind
// ends the process at once (the default action).
#include <signal.h>  // sigaction (POSIX)

#include <csignal>
#include <cstdint>
#include <string>

#include "basalt/solver/core/errors.hpp"

namespace basalt::solver {

/// The signal that asked the run to stop (0: none).
inline volatile std::sig_atomic_t stop_signal = 0;

/// Installs the recording handler for SIGTERM and SIGINT.
void install_stop_handlers();

/// "SIGTERM", "SIGINT", or "signal N".
const char* signal_name(int sig);

/// The RunError of a run stopped by a signal (on any rank): thrown alike on every rank, at step `step`.
class StopRequested : public RunError {
 public:
  StopRequested(const std::string& message, int sig, std::int64_t at_step)
      : RunError(message), signal(sig), step(at_step) {}
  int signal;
  std::int64_t step;
};

/// While it lives, SIGINT records a stop request (as install_stop_handlers' handler does) in place of the
/// handler that was there, which it puts back when it ends: Ctrl-C stops a run driven from Python at
/// the ranks' next agreement, which the caller then hands to Python's own handler (pending()). An
/// ignored or default SIGINT is left as it is. Clears stop_signal when it starts and when it ends.
class InterruptStopsRun {
 public:
  InterruptStopsRun();
  ~InterruptStopsRun();
  InterruptStopsRun(const InterruptStopsRun&) = delete;
  InterruptStopsRun& operator=(const InterruptStopsRun&) = delete;
  /// Puts the former handler back (once; the destructor calls it) and returns the signal recorded on
  /// this rank meanwhile (0: none).
  int restore();

 private:
  struct sigaction former_ {};
  bool installed_ = false;
};

}  // namespace basalt::solver
