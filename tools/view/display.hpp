#pragma once
// Debian's VTK 9.1 renders only through X. Without a display, basalt-view runs itself again under
// xvfb-run (a virtual X server), so that `basalt-view render` works on a headless machine as is.

namespace basalt::view {

/// When DISPLAY is unset and this process was not already started under xvfb-run by us,
/// replaces the process by `xvfb-run -a <this program> <args>` (never returns on success).
/// Throws std::runtime_error when xvfb-run is missing. BASALT_VIEW_NO_XVFB=1 disables it.
void ensure_display(int argc, char** argv);

}  // namespace basalt::view
