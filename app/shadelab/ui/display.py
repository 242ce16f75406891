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
