#pragma once
// Debian's VTK 9.1 renders only through X. Without a display, basalt-view starts its own virtual
// X server (Xvfb, package xvfb) for the duration of the command, so that `basalt-view render` works
// on a headless machine as is.

namespace basalt::view {

/// When DISPLAY is unset (and BASALT_VIEW_NO_XVFB is not), starts `Xvfb -displayfd`, which picks a
/// free display number itself (so concurrent commands never collide), sets DISPLAY, and stops the
/// server when this process exits (also if it dies: the server gets SIGTERM with its parent).
/// Throws std::runtime_error when Xvfb is missing or does not start within 20 s.
void ensure_display();

}  // namespace basalt::view
