"""Whether a window can be opened here: one line instead of GLFW's failure (which ends in an
ImGui assertion)."""

from __future__ import annotations

import os

from shadelab.errors import ShadeLabError

NO_DISPLAY = ("no display (DISPLAY and WAYLAND_DISPLAY are unset): run under xvfb-run "
              "(install Xvfb; 'xvfb-run -a shadelab'), or use 'shadelab render PRESET -o "
              "OUT.png'")


def check_display() -> None:
    """One line, before any window code, when no display can be opened (unset, or naming a
    server that is not there): GLFW's own failure ends in an ImGui assertion."""
    if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        raise ShadeLabError(NO_DISPLAY)
    opened = _x11_opens(os.environ.get("DISPLAY", ""))
    if opened is True:
        return
    if opened is False and not os.environ.get("WAYLAND_DISPLAY"):
        raise ShadeLabError(f"no display: cannot open '{os.environ['DISPLAY']}'; run under "
                            "xvfb-run, or use shadelab render")
    import glfw

    glfw.ERROR_REPORTING = "ignore"
    try:
        ok = glfw.init()
    except Exception:  # noqa: BLE001 - any failure of the probe means no usable display
        ok = False
    if not ok:
        where = os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
        raise ShadeLabError(f"no display: cannot open '{where}'; run under xvfb-run, or use "
                            "shadelab render")
    glfw.terminate()


def _x11_opens(display: str) -> bool | None:
    """Whether Xlib opens ``display`` (XOpenDisplay, then closed): a few milliseconds where
    GLFW's init and terminate took tens on the way to the first frame. None when there is no
    X display name or no libX11 here (then GLFW decides)."""
    if not display:
        return None
    import ctypes

    try:
        xlib = ctypes.CDLL("libX11.so.6")
    except OSError:
        return None
    xlib.XOpenDisplay.restype = ctypes.c_void_p
    xlib.XOpenDisplay.argtypes = [ctypes.c_char_p]
    xlib.XCloseDisplay.argtypes = [ctypes.c_void_p]
    handle = xlib.XOpenDisplay(display.encode())
    if not handle:
        return False
    xlib.XCloseDisplay(handle)
    return True
