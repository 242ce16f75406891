"""The viewer's start-up: the garbage collector paused from 'shadelab view' to the first frame
(shadelab.startup), and always running again afterwards."""

from __future__ import annotations

import gc

import pytest

from shadelab import startup
from shadelab.cli import main
from shadelab.errors import ShadeLabError
from shadelab.lab.state import AppState
from shadelab.scene import load_preset


@pytest.fixture(autouse=True)
def _collector_back_on():
    yield
    startup.resume_gc()
    gc.enable()


def test_pause_and_resume_turn_the_collector_off_and_on():
    assert gc.isenabled()
    startup.pause_gc()
    assert not gc.isenabled() and startup.gc_paused()
    startup.resume_gc()
    assert gc.isenabled() and not startup.gc_paused()


def test_a_collector_the_caller_turned_off_stays_off():
    gc.disable()
    startup.pause_gc()
    startup.resume_gc()
    assert not gc.isenabled()


def test_view_pauses_the_collector_and_a_bad_preset_resumes_it(monkeypatch, capsys):
    """Paused while the view command loads its scene; on again when it fails before a window."""
    from shadelab.scene import preset

    seen = []

    def failing_load(name, overrides=()):
        seen.append(gc.isenabled())
        raise ShadeLabError(f"unknown preset '{name}'")

    monkeypatch.setattr(preset, "load_preset", failing_load)
    monkeypatch.setenv("DISPLAY", ":12345")  # never reached
    assert main(["view", "no-such-preset", "--fresh"]) == 2
    assert seen == [False]
    assert gc.isenabled() and not startup.gc_paused()
    assert "unknown preset" in capsys.readouterr().err


def test_other_commands_leave_the_collector_on(monkeypatch, capsys, tmp_path):
    from shadelab.cli import render

    seen = []

    def failing_load(name, overrides=()):
        seen.append(gc.isenabled())
        raise ShadeLabError(f"unknown preset '{name}'")

    monkeypatch.setattr(render, "load_preset", failing_load)   # bound there at import
    assert main(["render", "no-such-preset", "-o", str(tmp_path / "never.png")]) == 2
    assert seen == [True]
    assert gc.isenabled()


def _viewer():
    from shadelab.ui.app import Viewer, ViewerOptions

    return Viewer(AppState.from_scene(load_preset("cornell"), "cornell"), ViewerOptions())


def test_the_first_frame_on_screen_resumes_the_collector():
    viewer = _viewer()
    startup.pause_gc()
    viewer.frame_swapped()                 # the dock space only: no scene yet
    assert not gc.isenabled()
    viewer.recorder.viewport_shown = True
    viewer.frame_swapped()                 # the first frame
    assert gc.isenabled() and not startup.gc_paused()


def test_the_collector_resumes_even_without_a_first_frame():
    from shadelab.ui.app import GC_RESUME_FRAME

    viewer = _viewer()
    startup.pause_gc()
    for frame in range(GC_RESUME_FRAME + 1):
        viewer.state.frame = frame
        viewer.frame_swapped()
    assert gc.isenabled()


def test_the_bench_holds_back_no_frame_before_the_first(monkeypatch):
    """While the bench waits for the warm-up it paces frames as an idle viewer does, from the
    first frame on screen: the frames before it are not slept on."""
    import time

    from shadelab.ui import app
    from shadelab.ui.app import Viewer, ViewerOptions

    slept = []
    monkeypatch.setattr(time, "sleep", slept.append)
    viewer = Viewer(AppState.from_scene(load_preset("cornell"), "cornell"),
                    ViewerOptions(frames=5, bench_json="unused.json"))
    viewer.warm_after_first_frame = True   # the warm-up has not started: not settled
    assert viewer.bench_phase(viewer.state) == 1 and slept == []
    viewer.recorder.viewport_shown = True
    viewer.recorder.frame_swapped()        # the first frame is on screen
    assert viewer.bench_phase(viewer.state) == 1 and slept == [app.SETTLE_FRAME_S]


@pytest.mark.gl
def test_the_overlay_programs_compile_when_first_drawn(gl_ctx):
    """A first frame without overlays compiles no line program; the first wireframe compiles
    the thin lines', thick lines the quads' (and both draw)."""
    import numpy as np

    from shadelab.ui.viewport import Viewport

    vp = Viewport(gl_ctx)
    try:
        scene = load_preset("cornell")
        pane = vp.draw_scene("main", scene, (64, 48), "phong", "blinn")
        assert "lines" not in vp._overlays and "thick_lines" not in vp._overlays
        before = pane.target.read().copy()
        segment = np.array([[50, 270, 280, 1, 0, 0], [500, 280, 280, 1, 0, 0]], dtype=np.float32)
        vp.draw_lines(pane, segment, 1.0, depth_test=False)
        assert "lines" in vp._overlays and "thick_lines" not in vp._overlays
        thin = pane.target.read().copy()
        assert np.any(thin != before)
        vp.line_width = 3.0
        vp.draw_lines(pane, segment, 1.0, depth_test=False)
        assert "thick_lines" in vp._overlays
        assert np.count_nonzero(np.any(pane.target.read() != before, axis=2)) > \
            np.count_nonzero(np.any(thin != before, axis=2))
    finally:
        vp.release()
    assert "lines" not in vp._overlays and "thick_lines" not in vp._overlays
