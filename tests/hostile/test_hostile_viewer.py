"""Issue 24, item 1: the viewer never hangs on a job started with its panel hidden, refuses
flags that point nowhere, and a typed nan / inf in a slider leaves no traceback."""

from __future__ import annotations

import json
import shutil

import pytest

from shadelab.cli.view import PANEL_LABELS

needs_xvfb = pytest.mark.skipif(shutil.which("xvfb-run") is None, reason="needs xvfb-run")


@pytest.mark.parametrize("flags, named", [
    (["--focus", "NoPanel"], "--focus"),
    (["--focus", "Scene,,Lights"], "--focus"),
    (["--probe", "99999,99999"], "--probe"),
    (["--probe", "99999,99999", "--window", "800x600"], "--probe"),
    (["--probe", "800,10", "--window", "800x600"], "--probe"),
    (["--ray-tree", "99999,5", "--job", "whitted"], "--ray-tree"),
    (["--ray-tree", "5,99999", "--job", "whitted"], "--ray-tree"),
    (["--ray-tree", "5,5"], "--ray-tree"),
    (["--ray-tree", "5,5", "--job", "path"], "--ray-tree"),
])
def test_a_viewer_flag_pointing_nowhere_is_one_line_exit_2(shadelab, flags, named):
    err = shadelab("view", "cornell", "--no-autosave", *flags, timeout=60)
    assert err.count("\n") == 1 and named in err, err


def test_the_panel_labels_are_the_dock_windows():
    from shadelab.lab.state import AppState
    from shadelab.scene import load_preset
    from shadelab.ui.app import Viewer, _docking
    from shadelab.ui.followups import ViewerOptions

    viewer = Viewer(AppState.from_scene(load_preset("cornell"), "cornell"), ViewerOptions())
    assert tuple(w.label for w in _docking(viewer).dockable_windows) == PANEL_LABELS


def test_a_typed_nan_or_inf_is_refused_by_every_slider_widget(monkeypatch):
    from imgui_bundle import imgui

    from shadelab.scene.model import Material
    from shadelab.ui import panels, ranges

    for bad in (float("nan"), float("inf"), -float("inf")):
        monkeypatch.setattr(imgui, "slider_float", lambda *a, _v=bad: (True, _v))
        monkeypatch.setattr(imgui, "drag_float3", lambda *a, _v=bad: (True, [0.0, _v, 1.0]))
        assert panels.slider("kd", 0.5, 0.0, 1.0) == (False, 0.5)
        assert ranges.field_slider(Material)("kd", 0.5) == (False, 0.5)
        assert panels.vec3("pos", (1.0, 2.0, 3.0), 0.1) == (False, (1.0, 2.0, 3.0))
    assert ranges.finite(True, 0.25, 0.5) == (True, 0.25)


def test_a_panel_error_is_one_stderr_line_once_not_a_traceback(capsys, monkeypatch):
    from shadelab.ui import frame

    monkeypatch.delenv("SHADELAB_DEBUG", raising=False)
    monkeypatch.setattr(frame, "_told", [])
    reported = []

    class FakeRecovery:  # guarded() outside a frame: its ImGui roll-back is not under test
        pass

    monkeypatch.setattr(frame.imgui.internal, "ErrorRecoveryState", FakeRecovery)
    monkeypatch.setattr(frame.imgui.internal, "error_recovery_store_state", lambda s: None)
    monkeypatch.setattr(frame.imgui.internal, "error_recovery_try_to_recover_state",
                        lambda s: None)

    class IO:
        config_error_recovery_enable_assert = True
        config_error_recovery_enable_tooltip = True

    monkeypatch.setattr(frame.imgui, "get_io", lambda: IO)

    def bad():
        raise ValueError("cannot convert float NaN to integer")
    for _ in range(3):  # the same error every frame: said once
        assert frame.guarded(bad, "materials panel", reported.append) is False
    err = capsys.readouterr().err
    assert err == "shadelab: materials panel: ValueError: cannot convert float NaN to integer\n"
    assert len(reported) == 3


@needs_xvfb
@pytest.mark.gui
@pytest.mark.slow
@pytest.mark.parametrize("window, extra", [
    ("1024x700", []),
    ("640x480", ["--ray-tree", "20,20"]),
])
def test_a_job_started_with_its_panel_hidden_ends_and_the_viewer_exits(shadelab, tmp_path,
                                                                       window, extra):
    shot = tmp_path / "window.png"
    shadelab("view", "cornell", "--fresh", "--no-autosave", "--job", "whitted", "--frames",
             "3", "--window", window, "--screenshot", str(shot), *extra, code=0, xvfb=True,
             timeout=400)
    assert shot.is_file()


@needs_xvfb
@pytest.mark.gui
def test_a_lesson_started_on_stage_shows_no_dock_window(shadelab, tmp_path):
    """`--lesson --presenter` opens on the stage: the tabs focused at start (Scene, Equation)
    and the step's focus panel stayed visible and drew over the stage's viewport."""
    report = tmp_path / "bench.json"
    shadelab("view", "--lesson", "phong-to-radiosity", "--step", "4", "--presenter",
             "--fresh", "--no-autosave", "--frames", "12", "--window", "1024x768",
             "--bench-json", str(report), code=0, xvfb=True, timeout=180)
    assert json.loads(report.read_text())["panels_visible"] == []


@needs_xvfb
@pytest.mark.gui
@pytest.mark.parametrize("flags", [
    ["--fullscreen"], ["--presenter", "--compare"], ["--pipeline", "gouraud"],
    ["--lesson", "phong-to-radiosity", "--step", "3"], ["--probe", "100,100"],
    ["--exercise", "phong-to-radiosity"], ["--focus", "Lights"],
    ["--lesson", "phong-to-radiosity", "--no-prefetch"],
])
def test_every_documented_viewer_flag_starts_draws_and_exits(shadelab, tmp_path, flags):
    """Each documented flag of `shadelab view` as a real process under Xvfb with a timeout
    (--fullscreen asked imgui-bundle for a FullScreenMode member it does not have: exit 1)."""
    shot = tmp_path / "window.png"
    shadelab("view", "lecture", "--fresh", "--no-autosave", "--frames", "5", "--window",
             "1024x768", "--screenshot", str(shot), *flags, code=0, xvfb=True, timeout=180)
    assert shot.is_file()
