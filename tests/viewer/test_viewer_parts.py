"""The pieces taken out of the Viewer (issue 11.7): the autosave, the probe's read-back and the
viewport screenshot, each without a window."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from shadelab.lab import autosave as autosave_module
from shadelab.lab.autosave import Autosave
from shadelab.lab.state import AUTOSAVE_INTERVAL, AppState, autosave_path
from shadelab.scene import load_preset
from shadelab.ui.viewport_reads import update_probe, write_viewport_screenshot


def _state() -> AppState:
    return AppState.from_scene(load_preset("cornell"), "cornell")


# ---------------------------------------------------------------- autosave


def test_autosave_writes_a_changed_scene_at_most_once_per_interval(monkeypatch):
    clock = [100.0]
    monkeypatch.setattr(autosave_module.time, "perf_counter", lambda: clock[0])
    state, save = _state(), Autosave()
    save(state)
    assert not autosave_path().exists()          # nothing changed: nothing written
    state.scene.materials["white"].kd = 0.5
    state.mark_edited()
    save(state)
    assert not autosave_path().exists()          # mid-edit (a slider still held): not yet
    state.commit_edit()
    save(state)
    assert autosave_path().exists() and not state.autosave_due
    assert "kd = 0.5" in autosave_path().read_text()
    state.scene.materials["white"].kd = 0.25
    state.mark_edited()
    state.commit_edit()
    clock[0] += AUTOSAVE_INTERVAL / 2
    save(state)
    assert state.autosave_due                    # too soon after the last write
    clock[0] += AUTOSAVE_INTERVAL
    save(state)
    assert not state.autosave_due and "kd = 0.25" in autosave_path().read_text()


def test_autosave_at_exit_is_forced_even_mid_edit(monkeypatch):
    monkeypatch.setattr(autosave_module.time, "perf_counter", lambda: 5.0)
    state, save = _state(), Autosave(last=5.0)
    state.scene.materials["white"].kd = 0.75
    state.mark_edited()                          # still pending, and within the interval
    save(state, force=True)
    assert not state.autosave_due and "kd = 0.75" in autosave_path().read_text()


def test_a_failing_autosave_is_one_line_and_the_session_goes_on(monkeypatch):
    def full_disk(scene, source):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(autosave_module, "save_session", full_disk)
    state, save = _state(), Autosave()
    state.mark_edited()
    state.commit_edit()
    save(state)
    assert state.error == "autosave failed: [Errno 28] No space left on device"
    assert state.autosave_due                    # tried again later


# ---------------------------------------------------------------- viewport screenshot


class _Shown:
    """A viewport whose main pane shows ``image`` (what read_display gives)."""

    def __init__(self, image: np.ndarray):
        self.image = image

    def read_display(self, key: str) -> np.ndarray:
        assert key == "main"
        return self.image.copy()


def test_viewport_screenshot_is_the_shown_image(tmp_path, np_rng):
    image = np_rng.integers(0, 256, (30, 40, 3), dtype=np.uint8)
    state = _state()
    state.view.legend_in_screenshot = False
    path = tmp_path / "shot.png"
    write_viewport_screenshot(state, _Shown(image), str(path))
    np.testing.assert_array_equal(np.asarray(Image.open(path)), image)
    assert state.status == f"screenshot {path}" and not state.error
    state.view.legend_in_screenshot = True            # the legend is burnt into the pixels
    write_viewport_screenshot(state, _Shown(image), str(path))
    assert not np.array_equal(np.asarray(Image.open(path)), image)


def test_viewport_screenshot_to_a_bad_path_is_one_line(tmp_path):
    state = _state()
    (tmp_path / "a-file").write_text("a file where a folder is expected")
    path = tmp_path / "a-file" / "shot.png"   # (a missing folder is made: the Pictures one)
    write_viewport_screenshot(state, _Shown(np.zeros((4, 4, 3), np.uint8)), str(path))
    assert state.error.startswith(f"screenshot '{path}': cannot write (")
    assert "\n" not in state.error and not path.exists()


# ---------------------------------------------------------------- probe read-back


@pytest.mark.gl
@pytest.mark.parametrize("samples", [1, 4])
def test_probe_maps_the_shown_pixel_to_the_rendered_one_and_reads_the_gpu(gl_ctx, samples):
    from shadelab.ui.viewport import Viewport

    state = _state()
    scene = state.scene
    size, display = (40, 30), (80, 60)           # render scale 1/2
    vp = Viewport(gl_ctx)
    try:
        vp.draw_scene("main", scene, size, scene.render.shading, scene.render.specular,
                      samples)
        state.probe.pixel, state.probe.requested = (41, 33), True
        update_probe(state, vp, size, display, samples)
        assert not state.probe.requested and state.probe.version == 1
        assert state.probe.result.pixel == (20, 16)      # (41 * 40 / 80, 33 * 30 / 60)
        key = "probe" if samples > 1 else "main"  # MSAA: one sample, drawn again
        np.testing.assert_array_equal(state.probe.result.gpu, vp.read_pixel(key, (20, 16)))
        assert ("probe" in vp.panes) == (samples > 1)
        np.testing.assert_allclose(state.probe.result.gpu, state.probe.result.reference, rtol=1e-4,
                                   atol=1e-5)
        state.probe.pixel = (80, 10)              # off the viewport: no probe
        update_probe(state, vp, size, display, samples)
        assert state.probe.result is None and state.probe.version == 2
    finally:
        vp.release()
