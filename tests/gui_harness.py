"""What every GUI test module shares: a private Xvfb server for the pytest side, and the
scenario runner each module's script side calls (``python3 tests/test_gui_X.py NAME OUTDIR``).

The pytest side starts the script in its own process (a fresh GLFW window and GL context) on
the private display; the script runs one ``scenario_NAME(ctx, state, out)`` under the ImGui
Test Engine and writes ``out`` as ``OUTDIR/NAME.json`` for the pytest side to assert on.
"""

from __future__ import annotations

import json
import os
import select
import shutil
import subprocess
from pathlib import Path

import pytest


def private_xvfb(screen: str, why: str = "GUI tests need a display",
                 failed: str = "Xvfb did not start"):
    """Generator for a fixture: start ``Xvfb -screen 0 SCREEN`` on a free display, yield its
    DISPLAY string, end it afterwards; skipped (with the reason) when Xvfb is missing or
    cannot make that screen. Use as ``yield from private_xvfb("1344x784x24")``."""
    if shutil.which("Xvfb") is None:
        pytest.skip(f"Xvfb is not installed (apt-get install xvfb): {why}")
    read_fd, write_fd = os.pipe()
    proc = subprocess.Popen(["Xvfb", "-displayfd", str(write_fd), "-screen", "0", screen,
                             "-nolisten", "tcp"], pass_fds=(write_fd,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write_fd)
    ready, _, _ = select.select([read_fd], [], [], 20.0)
    number = os.read(read_fd, 64).decode().strip() if ready else ""
    try:
        if not number or proc.poll() is not None:
            pytest.skip(failed)
        yield f":{number}"
    finally:
        proc.terminate()
        proc.wait(10)
        os.close(read_fd)  # only now: Xvfb dies of SIGPIPE if it writes to a closed pipe


def capture(ctx, path: str) -> None:
    """A PNG of the window without the mouse cursor."""
    from imgui_bundle import imgui
    from imgui_bundle.immapp import testing

    testing.capture(ctx, path, flags=imgui.test_engine.CaptureFlags_.hide_mouse_cursor)


def run_scenario_main(scenarios: dict, name: str, out_dir: str, preset: str = "cornell",
                      window_size: tuple[int, int] = (1280, 720), **options) -> int:
    """The script side: open the viewer on ``preset`` and run ``scenarios[f"scenario_{name}"]``
    under the test engine; ``options`` go to :class:`ViewerOptions`."""
    from shadelab.lab.state import AppState
    from shadelab.scene import load_preset
    from shadelab.ui.app import ViewerOptions, run_viewer

    scenario = scenarios[f"scenario_{name}"]
    out: dict = {}
    state = AppState.from_scene(load_preset(preset), preset)
    state.screenshot_dir = out_dir

    def body(ctx, state):
        # The engine's watchdog ends a test after 60 s of wall time; at 3840x2160 on llvmpipe,
        # with the other test worker busy on 2 cores, a layout walk takes longer than that
        # without being stuck. pytest's own timeout (run_scenario) still bounds every run.
        from imgui_bundle import hello_imgui, imgui

        io = imgui.test_engine.get_io(hello_imgui.get_imgui_test_engine())
        io.config_watchdog_warning = WATCHDOG_S / 2
        io.config_watchdog_kill_test = WATCHDOG_S
        io.config_watchdog_kill_app = WATCHDOG_S + 30
        scenario(ctx, state, out)

    run_viewer(state, ViewerOptions(window_size=window_size, test_function=body, **options))
    Path(out_dir, f"{name}.json").write_text(json.dumps(out))
    return 0


WATCHDOG_S = 400.0  # seconds a scenario may run before the test engine aborts it
GL_MODULES = ("moderngl", "OpenGL", "glfw", "shadelab.gl", "shadelab.raster",
              "shadelab.ui.viewport", "shadelab.ui.gpu_side")


def gl_objects_in(state) -> list[str]:
    """Where a GL object hangs in the state the panels see: the AppState's fields (and the
    Hemicube window's view of it), walked through dataclasses, dicts, lists and the
    attributes of shadelab objects; ``[]`` when the state is plain data."""
    from shadelab.ui import radiosity_view

    found, seen = [], set()
    todo = [("state", state), ("radiosity_view", radiosity_view._views.get(id(state)))]
    while todo:
        path, obj = todo.pop()
        if obj is None or id(obj) in seen or isinstance(obj, (str, bytes, int, float, bool)):
            continue
        seen.add(id(obj))
        module = type(obj).__module__ or ""
        if any(module == m or module.startswith(m + ".") for m in GL_MODULES):
            found.append(f"{path}: {module}.{type(obj).__name__}")
            continue
        if isinstance(obj, dict):
            todo += [(f"{path}[{k!r}]", v) for k, v in obj.items()]
        elif isinstance(obj, (list, tuple, set)):
            todo += [(f"{path}[{i}]", v) for i, v in enumerate(obj)]
        elif module.startswith("shadelab.") and hasattr(obj, "__dict__"):
            todo += [(f"{path}.{k}", v) for k, v in vars(obj).items()]
    return sorted(found)
