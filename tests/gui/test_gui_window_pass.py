"""The viewport's display pass straight into the window (issue 25; ui.app.WINDOW_PASS), and
on idle frames its display texture copied there: the window shows the bytes the texture path
showed, redrawn and idle, docked and on stage, and what reads the pane's display
(screenshots, probes) still gets them.

Run one scenario by hand:  xvfb-run -a python3 tests/gui/test_gui_window_pass.py docked /tmp/o
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/: gui_harness
sys.path.insert(0, str(Path(__file__).resolve().parent))      # tests/gui: test_gui
from test_gui import run_scenario  # noqa: E402

from gui_harness import capture, private_xvfb, run_scenario_main  # noqa: E402

pytestmark = pytest.mark.gui
SIZES = {"docked": (1280, 720), "stage": (1024, 768)}
OUT_DIR = "."


@pytest.fixture(scope="module")
def display():
    yield from private_xvfb("1344x832x24")


@pytest.mark.parametrize("name", sorted(SIZES))
def test_the_window_pass_shows_what_the_texture_showed(display, tmp_path, name):
    from PIL import Image

    r = run_scenario(name, display, tmp_path, script=__file__, timeout=150)
    assert r["texture_path_drew_none"]
    assert r["redraw_displays"] >= 1                              # the redraw: a display pass
    assert r["idle_copies"] >= 5 and r["idle_displays"] == 0      # idle: copies of it
    x0, y0, w, h = r["rect"]   # the viewport in window pixels, row 0 at the top
    shots = {k: np.asarray(Image.open(tmp_path / f"{k}.png").convert("RGB"))[y0:y0 + h,
                                                                            x0:x0 + w]
             for k in ("window", "window-idle", "texture")}
    # the fps readout sits in the viewport's corner and changes frame to frame: left out
    keep = np.ones((h, w), bool)
    keep[: r["readout_rows"], w - r["readout_cols"]:] = False
    for k in ("window", "window-idle"):
        assert np.array_equal(shots[k][keep], shots["texture"][keep]), k
    display_read = np.asarray(Image.open(tmp_path / "read_display.png").convert("RGB"))
    assert display_read.shape == (h, w, 3)
    assert np.array_equal(display_read[keep], shots["window"][keep])


def _scenario(ctx, state, out: dict, stage: bool) -> None:
    from imgui_bundle import imgui

    import shadelab.ui.app as app
    from shadelab.ui.app import running_viewer

    viewer = running_viewer()
    if stage:   # presenter mode with the panels hidden: the viewport over the whole window
        state.view.presenter = state.view.hide_panels = True
    ctx.yield_(10)
    app.WINDOW_PASS = False
    state.mark_edited()
    ctx.yield_(3)
    passes = dict(viewer.window_passes)
    capture(ctx, str(Path(OUT_DIR) / "texture.png"))
    out["texture_path_drew_none"] = viewer.window_passes == passes
    app.WINDOW_PASS = True
    state.mark_edited()
    ctx.yield_(1)
    out["redraw_displays"] = viewer.window_passes["display"] - passes["display"]
    capture(ctx, str(Path(OUT_DIR) / "window.png"))
    passes = dict(viewer.window_passes)
    ctx.yield_(5)   # idle frames: the cached image copied into the window
    out["idle_copies"] = viewer.window_passes["copy"] - passes["copy"]
    out["idle_displays"] = viewer.window_passes["display"] - passes["display"]
    capture(ctx, str(Path(OUT_DIR) / "window-idle.png"))
    # the viewport's own screenshot reads the pane's display (read_display, on the UI thread:
    # this coroutine has no GL context), which the window pass left to be drawn on demand
    state.view.legend_in_screenshot = False
    state.screenshot_requested = str(Path(OUT_DIR) / "read_display.png")
    for _ in range(50):
        ctx.yield_(1)
        if not state.screenshot_requested:
            break
    rect = viewer.last_window_rect
    height = int(imgui.get_io().display_size.y)
    out["rect"] = [rect[0], height - rect[1] - rect[3], rect[2], rect[3]]
    out["readout_rows"], out["readout_cols"] = 40, 260


def scenario_docked(ctx, state, out: dict) -> None:
    _scenario(ctx, state, out, stage=False)


def scenario_stage(ctx, state, out: dict) -> None:
    _scenario(ctx, state, out, stage=True)


def _main(name: str, out_dir: str) -> int:
    global OUT_DIR
    OUT_DIR = out_dir
    return run_scenario_main(globals(), name, out_dir, "lecture", SIZES[name],
                             autosave=False)


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1], sys.argv[2]))
