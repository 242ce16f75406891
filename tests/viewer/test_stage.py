"""What the class sees: the Pipeline selector agrees with the Shading radio after any change of
the scene's shading (a lesson step back, undo), and no fps readout in presenter mode unless
asked (issue 22)."""

from __future__ import annotations

from shadelab.lab.pipeline_view import current, set_pipeline
from shadelab.lab.state import AppState, ViewState
from shadelab.scene.preset import load_preset


def test_the_pipeline_selector_follows_the_scenes_shading():
    state = AppState.from_scene(load_preset("lecture"), "lecture")
    set_pipeline(state, "phong")
    assert current(state) == "phong" and state.scene.render.shading == "phong"
    state.scene.render.shading = "gouraud"      # what stepping back to a Gouraud step does
    assert current(state) == "gouraud"          # before: "phong" (z-buffer + Phong)
    state.scene.render.visibility = "painter"
    assert current(state) == "painter"
    set_pipeline(state, "raytrace")             # an offline choice is its own truth
    assert current(state) == "raytrace"


def test_no_fps_readout_in_presenter_mode_unless_asked():
    view = ViewState()
    assert view.show_fps and view.fps_shown     # on at the desk
    view.presenter = True
    assert not view.fps_shown                   # off in front of the class
    view.fps_in_presenter = True
    assert view.fps_shown
    view.show_fps = False
    assert not view.fps_shown


def test_screenshots_go_to_the_pictures_folder_and_are_announced(tmp_path, monkeypatch):
    import numpy as np

    from shadelab.lab.state import default_screenshot_dir
    from shadelab.ui.viewport_reads import write_viewport_screenshot

    monkeypatch.delenv("SHADELAB_SCREENSHOT_DIR", raising=False)
    monkeypatch.setenv("XDG_PICTURES_DIR", str(tmp_path / "Bilder"))
    assert default_screenshot_dir() == str(tmp_path / "Bilder" / "ShadeLab")
    monkeypatch.delenv("XDG_PICTURES_DIR")
    monkeypatch.setenv("HOME", str(tmp_path))
    assert default_screenshot_dir() == str(tmp_path / "Pictures" / "ShadeLab")
    state = AppState.from_scene(load_preset("cornell"), "cornell")
    assert state.screenshot_dir == str(tmp_path / "Pictures" / "ShadeLab")

    class Shown:
        def read_display(self, key):
            return np.zeros((30, 40, 3), np.uint8)

    path = tmp_path / "Pictures" / "ShadeLab" / "shot.png"   # the folder is made on the save
    write_viewport_screenshot(state, Shown(), str(path))
    assert path.is_file() and not state.error
    assert state.toast[0] == f"saved {path}"
