#pragma once
// A request to stop the run early (SIGTERM, SIGINT): the handler only records the signal; the run loop
// looks at it where the compute ranks already agree on output errors (every 32 steps and at output
// steps), so that all stop at the same step, hand over the field rows computed so far, let the I/O
// ranks finish what they hold, and exit non-zero with a message. A second signal of the same kind
// ends the process at once (the default action).
#include <csignal>

namespace basalt::solver {

/// The signal that asked the run to stop (0: none).
inline volatile std::sig_atomic_t stop_signal = 0;

/// Installs the recording handler for SIGTERM and SIGINT.
void install_stop_handlers();

/// "SIGTERM", "SIGINT", or "signal N".
const char* signal_name(int sig);

}  // namespace basalt::solver
