"""An X display for VTK on a headless machine: Debian's VTK 9.1 draws through X11 only (its off-screen window
still needs an X connection). When DISPLAY is unset, the first picture starts a virtual X server (Xvfb) for
the rest of the process, as basalt-view does (docs/basalt-view.md, "No display needed"): displays from :99
up (hwloc, inside MPI_Init, probes :0-:9 and an X server that comes and goes there breaks MPI start-up), the
next number when one is taken, `-noreset` (a server resets when its last client leaves), stopped at exit and
killed with the process (setpriv --pdeathsig)."""

import atexit
import ctypes
import ctypes.util
import os
import select
import shutil
import subprocess

_server = None  # the Xvfb process this process started
_connection = None  # an Xlib connection to DISPLAY, kept open (_check)


class NoDisplayError(RuntimeError):
    """No X display: DISPLAY is unset and no virtual X server could be started."""


def _stop():
    global _server
    if _server is not None and _server.poll() is None:
        _server.terminate()
        try:
            _server.wait(timeout=10)
        except subprocess.TimeoutExpired:
            _server.kill()
            _server.wait()
    _server = None


def _start(number, timeout=20.0):
    """Starts Xvfb on display `number`; True once it listens, False when it exits at once (the display is
    taken). Raises NoDisplayError when it does not answer within `timeout` seconds."""
    global _server
    read_fd, write_fd = os.pipe()
    cmd = ["Xvfb", f":{number}", "-displayfd", str(write_fd), "-screen", "0", "1920x1200x24",
           "-nolisten", "tcp", "-noreset"]
    setpriv = shutil.which("setpriv")
    if setpriv:
        cmd = [setpriv, "--pdeathsig", "TERM", "--"] + cmd
    try:
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL, pass_fds=(write_fd,), close_fds=True)
    finally:
        os.close(write_fd)
    answer = b""
    try:
        while not answer.endswith(b"\n"):
            ready, _, _ = select.select([read_fd], [], [], timeout)
            if not ready:
                proc.kill()
                proc.wait()
                raise NoDisplayError("no X display (DISPLAY is unset) and the virtual X server (Xvfb) did not "
                                     f"answer within {timeout:g} s")
            chunk = os.read(read_fd, 64)
            if not chunk:  # the server exited without listening: the display is taken
                proc.wait()
                return False
            answer += chunk
    finally:
        os.close(read_fd)
    _server = proc
    atexit.register(_stop)
    return True


def _check(display):
    """Raises NoDisplayError when `display` does not answer (VTK would abort the process instead). The
    connection stays open until the process ends: an X server started without -noreset (xvfb-run's) resets
    when its last client leaves and refuses clients during the reset, and VTK opens and closes connections."""
    global _connection
    if _connection is not None:
        return
    lib = ctypes.util.find_library("X11")
    if lib is None:
        return  # let VTK try
    x11 = ctypes.CDLL(lib)
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
    d = x11.XOpenDisplay(display.encode())
    if not d:
        raise NoDisplayError(f"cannot open the X display DISPLAY={display}: unset DISPLAY to draw on a virtual X "
                             "server (Xvfb) of the process's own")
    _connection = d


def ensure_display():
    """Makes sure VTK finds an X display: DISPLAY as set, or a virtual X server of this process's own
    (BASALT_VIEW_NO_XVFB=1 switches that off, as for basalt-view). Returns the display's name."""
    if _server is not None:  # ours, started with -noreset
        return os.environ["DISPLAY"]
    if os.environ.get("DISPLAY"):
        _check(os.environ["DISPLAY"])
        return os.environ["DISPLAY"]
    if os.environ.get("BASALT_VIEW_NO_XVFB"):
        raise NoDisplayError("no X display: DISPLAY is unset and BASALT_VIEW_NO_XVFB is set")
    if shutil.which("Xvfb") is None:
        raise NoDisplayError("no X display (DISPLAY is unset) and Xvfb is not installed: apt-get install xvfb, "
                             "or set DISPLAY")
    for number in range(99, 99 + 400):
        if _start(number):
            os.environ["DISPLAY"] = f":{number}"
            return os.environ["DISPLAY"]
    raise NoDisplayError("no X display (DISPLAY is unset) and no virtual X server (Xvfb) could be started")
