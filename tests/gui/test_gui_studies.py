"""The viewer's Studies and Failure gallery panels.

Unit tests of :mod:`shadelab.lab.studies` (no window), then two GUI scenarios on the real viewer
under a private Xvfb (the ``xdisplay`` fixture and helpers of tests/gui/test_gui.py), each in its
own process like the scenarios there.

Run one scenario by hand:  xvfb-run -a python3 tests/gui/test_gui_studies.py gallery /tmp/out
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/: gui_harness
from test_gui import _wait, run_scenario, xdisplay  # noqa: F401  (private Xvfb, helpers)

from gui_harness import run_scenario_main  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SCENARIO_TIMEOUT = 60  # seconds per scenario process


# ---------------------------------------------------------------- unit tests (no window)


def _state(preset: str = "cornell"):
    from shadelab.lab.state import AppState
    from shadelab.scene import load_preset

    return AppState.from_scene(load_preset(preset), preset)


def test_load_case_scene_applies_overrides_and_the_raster_shading():
    from shadelab.lab.studies import case_shading, load_case_scene, offline_job_of
    from shadelab.studies.gallery import case_named

    scene = load_case_scene(case_named("flat-curved"))
    assert scene.render.shading == "flat" and scene.objects[0].subdivisions == 2
    assert load_case_scene(case_named("gouraud-highlight")).render.shading == "gouraud"
    assert case_shading(case_named("shadow-acne")) is None
    assert offline_job_of(case_named("shadow-acne")) == "raytrace"   # registry names
    assert offline_job_of(case_named("radiosity-light-leak")) == "radiosity"
    assert offline_job_of(case_named("mach-bands")) == ""


def test_open_case_replaces_the_scene_like_open_preset():
    from shadelab.lab.studies import open_case
    from shadelab.studies.gallery import case_named

    state = _state()
    state.scene.materials["white"].kd = 0.3
    state.mark_edited()
    state.commit_edit()
    assert state.history.can_undo()
    assert open_case(state, case_named("shininess-huge"))
    assert state.source == "fail-coefficients" and state.studies.gallery_opened == "shininess-huge"
    assert state.scene.materials["paint"].n == 10000.0 and state.scene.render.shading == "phong"
    assert not state.dirty and state.error == ""
    # opening a case is one undoable step, like loading a preset: undo brings the edit back
    assert state.history.can_undo()
    state.undo()
    assert state.scene.materials["white"].kd == 0.3 and "paint" not in state.scene.materials
    state.redo()
    assert state.scene.materials["paint"].n == 10000.0
    assert open_case(state, case_named("total-internal-reflection"))
    assert "Whitted" in state.status and state.source == "fail-tir"


def test_a_broken_case_shows_the_error_and_keeps_the_scene():
    from shadelab.lab.studies import open_case
    from shadelab.studies.gallery import GalleryCase

    state = _state()
    scene = state.scene
    broken = GalleryCase("broken", "cornell", ("materials.nope.kd=1",), "raster:phong", "x", "t")
    assert not open_case(state, broken)
    assert state.scene is scene and state.source == "cornell"
    assert state.error.startswith("gallery case 'broken': ") and "nope" in state.error
    missing = GalleryCase("missing", "no-such-preset", (), "raster:phong", "x", "t")
    assert not open_case(state, missing) and "no-such-preset" in state.error
    assert state.scene is scene


def _toy_result(**kwargs):
    from shadelab.studies.result import StudyResult

    rows = [["a", 1, 1.0, 0.5], ["a", 2, 2.0, 0.1], ["a", 3, 4.0, 0.0],
            ["b", 1, 1.5, 0.05], ["b", 2, 3.0, 0.2], ["b", 3, "n/a", 0.01]]
    return StudyResult(name="toy", title="toy", columns=["method", "level", "time_ms", "relmse"],
                       rows=rows, x="time_ms", y="relmse", group="method", label="level",
                       **kwargs)


def test_plot_series_groups_rows_and_floors_zero_errors_on_a_log_axis():
    from shadelab.lab.studies import plot_series

    series = {name: (xs, ys, labels) for name, xs, ys, labels in plot_series(_toy_result())}
    assert list(series) == ["a", "b"]
    assert series["a"] == ([1.0, 2.0, 4.0], [0.5, 0.1, 0.001], ["1", "2", "3"])  # 0 -> 0.01/10
    assert series["b"] == ([1.5, 3.0], [0.05, 0.2], ["1", "2"])  # the "n/a" time is left out
    linear = {n: ys for n, _, ys, _ in plot_series(_toy_result(log_y=False))}
    assert linear["a"] == [0.5, 0.1, 0.0]


def test_auto_quality_picks_the_cheapest_front_point_within_the_budget():
    from shadelab.lab.studies import auto_quality_line, study_front

    result = _toy_result()
    front = study_front(result)
    assert len(front) == 5 and front[0].setting == {"method": "a", "level": 1}
    # front by cost: a1 (1.0, 0.5), b1 (1.5, 0.05), a3 (4.0, 0.0)
    assert "method b, level 1" in auto_quality_line(result, 0.1)
    assert "meets" in auto_quality_line(result, 0.1)
    assert "method a, level 1" in auto_quality_line(result, 0.6)
    assert "method a, level 3" in auto_quality_line(result, 0.01)
    assert "no speed/accuracy front" in auto_quality_line(_toy_result(front=False), 0.1)
    assert "expected a finite error budget" in auto_quality_line(result, 0.0)


def test_study_run_takes_the_result_or_the_error(monkeypatch):
    import time

    import shadelab.studies
    from shadelab.lab.jobs import JobRunner
    from shadelab.lab.studies import StudyRun

    def wait(run):
        deadline = time.perf_counter() + 10
        while run.running and time.perf_counter() < deadline:
            time.sleep(0.01)
        run.poll()

    monkeypatch.setitem(shadelab.studies._STUDY_TABLE, "ghost",
                        ("shadelab.studies.no_such_study", "run_ghost", "not built"))
    run = StudyRun(runner=JobRunner(use_process=False))
    run.start("ghost")
    wait(run)
    assert run.result is None and "no_such_study" in run.error  # a broken import fails
    toy = _toy_result()
    monkeypatch.setattr(shadelab.studies, "run_study", lambda name, quick: toy)
    run.start("toy")
    wait(run)
    assert run.result is toy and run.error == ""


def test_focus_takes_a_list_and_word_matches():
    from imgui_bundle import hello_imgui

    from shadelab.ui.layout import focus_windows

    windows = []
    for label, dock in (("Scene", "Left"), ("Lights", "Left"), ("Equation & probe", "Right"),
                        ("Studies", "Right"), ("Failure gallery", "Right")):
        w = hello_imgui.DockableWindow()
        w.label, w.dock_space_name = label, dock
        windows.append(w)
    assert focus_windows(windows, "gallery") == ["Failure gallery"]
    assert [w.focus_window_at_next_frame for w in windows] == [False, False, False, False, True]
    assert focus_windows(windows, "lights, studies") == ["Lights", "Studies"]
    assert [w.focus_window_at_next_frame for w in windows] == [False, True, False, True, False]


@pytest.mark.parametrize("flag, value, expected", [
    ("--study", "nope", "--study 'nope': expected one of shading, raytrace"),
    ("--gallery", "nope", "--gallery 'nope': expected one of gouraud-highlight"),
])
def test_view_rejects_an_unknown_study_or_case(monkeypatch, capsys, flag, value, expected):
    from shadelab.cli import main

    monkeypatch.setenv("DISPLAY", ":987")
    assert main(["view", "--fresh", flag, value]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and expected in err[0]


# ---------------------------------------------------------------- GUI scenarios (pytest side)


def _run_scenario(name: str, display: str, tmp_path: Path) -> dict:
    return run_scenario(name, display, tmp_path, script=__file__, timeout=SCENARIO_TIMEOUT)


@pytest.mark.gui
def test_gallery_opens_cases_in_the_viewer(xdisplay, tmp_path):  # noqa: F811
    r = _run_scenario("gallery", xdisplay, tmp_path)
    assert r["before"] == ["cornell", "phong"]
    assert r["gouraud"] == ["fail-gouraud-highlight", "gouraud", ""]
    assert r["flat"] == ["sphere-shading", "flat", 2, ""]   # both --set overrides applied
    assert r["broken"][0] == "sphere-shading" and "nope" in r["broken"][1]  # scene kept
    assert r["frames_drawn"] >= 3
    # an offline case opens its preset (raytrace.offset=0 applied) and starts its renderer
    assert r["offline"] == ["fail-shadow-acne", 0.0, "Whitted ray tracer", ""]


@pytest.mark.gui
def test_studies_panel_runs_the_quick_shading_study_off_the_ui_thread(xdisplay,  # noqa: F811
                                                                    tmp_path):
    r = _run_scenario("studies", xdisplay, tmp_path)
    assert r["name"] == "shading" and r["rows"] == 18 and r["error"] == ""
    assert r["columns"][:4] == ["method", "level", "triangles", "time_ms"]
    assert r["plotted"] == r["rows"]          # every row is a point of the chart
    assert r["frames_while_running"] >= 10    # the UI kept drawing while the study ran
    assert r["auto_quality"].startswith("auto quality: method ")


# ---------------------------------------------------------------- scenario side (subprocess)


def scenario_gallery(ctx, state, out: dict) -> None:
    from shadelab.studies.gallery import GALLERY, GalleryCase

    GALLERY.insert(0, GalleryCase("broken-test-case", "cornell", ("materials.nope.kd=1",),
                               "raster:phong", "a case whose override names no material", "t"))
    ctx.yield_(3)
    out["before"] = [state.source, state.scene.render.shading]
    ctx.window_focus("//Failure gallery")
    ctx.set_ref("//Failure gallery")
    frame0 = state.frame
    ctx.item_click("**/gouraud-highlight  (raster:gouraud)")
    ctx.item_click("Open in viewer")
    _wait(ctx, lambda: state.studies.gallery_opened == "gouraud-highlight", 60)
    out["gouraud"] = [state.source, state.scene.render.shading, state.error]
    ctx.item_click("**/flat-curved  (raster:flat)")
    ctx.item_click("Open in viewer")
    _wait(ctx, lambda: state.studies.gallery_opened == "flat-curved", 60)
    out["flat"] = [state.source, state.scene.render.shading, state.scene.objects[0].subdivisions,
                   state.error]
    ctx.item_click("**/broken-test-case  (raster:phong)")
    ctx.item_click("Open in viewer")
    _wait(ctx, lambda: bool(state.error), 60)
    out["broken"] = [state.source, state.error]
    state.error, state.offline.size = "", 32
    state.studies.gallery_index = [c.name for c in GALLERY].index("shadow-acne")
    ctx.yield_(2)
    ctx.item_click("Run offline job")
    _wait(ctx, lambda: state.offline.runner.started, 60)
    out["offline"] = [state.source, state.scene.raytrace.offset, state.offline.runner.name,
                      state.error]
    state.offline.runner.cancel(wait=True)
    ctx.yield_(2)
    out["frames_drawn"] = state.frame - frame0


def scenario_studies(ctx, state, out: dict) -> None:
    from shadelab.lab.studies import auto_quality_line

    ctx.yield_(3)
    ctx.window_focus("//Studies")
    ctx.set_ref("//Studies")
    ctx.item_click("Run (quick)")
    _wait(ctx, lambda: state.studies.run is not None and state.studies.run.running, 60)
    frame0 = state.frame
    _wait(ctx, lambda: not state.studies.run.running, 3000)
    out["frames_while_running"] = state.frame - frame0
    _wait(ctx, lambda: state.studies.plotted > 0, 30)
    result = state.studies.run.result
    out["error"] = state.studies.run.error
    out["name"] = result.name if result else ""
    out["rows"] = len(result.rows) if result else 0
    out["columns"] = list(result.columns) if result else []
    out["plotted"] = state.studies.plotted
    out["auto_quality"] = auto_quality_line(result, state.studies.budget) if result else ""


def _main(name: str, out_dir: str) -> int:
    return run_scenario_main(globals(), name, out_dir, "cornell", (1280, 720))


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1], sys.argv[2]))
