"""Radiosity at lecture pace (issue 19.1), under Xvfb at 1024x768 in presenter mode: the
lesson's Radiosity step, step mode shot by shot with and without the ambient estimate, the
shooting patch's outline in the window's pixels, the Hemicube & F window's buttons, toggles,
face labels and the solver's rows of F.

Run one by hand:  xvfb-run -a python3 tests/gui/test_gui_radiosity_teaching.py teaching /tmp/out
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_gui import _wait, run_scenario  # noqa: E402

from gui_harness import capture, private_xvfb, run_scenario_main  # noqa: E402

pytestmark = pytest.mark.gui
WINDOW = (1024, 768)
PANEL = "Hemicube & F"
CONTROLS = ("Progressive refinement:", "Step mode", "Shoot next patch", "Play",
            "ambient estimate", "patch grid")


@pytest.fixture(scope="module")
def display():
    yield from private_xvfb("1184x864x24")


@pytest.fixture(scope="module")
def teaching(display, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("teaching")
    return run_scenario("teaching", display, tmp, script=__file__, timeout=400), tmp


def test_the_step_starts_without_grid_or_ambient_on_the_hemicube(teaching):
    r, _ = teaching
    assert r["step"] == {"patches_grid": False, "ambient": False, "form_factors": "hemicube",
                         "pipeline": "radiosity", "gizmos_hidden": True}


def test_buttons_and_toggles_are_inside_the_window_at_1024x768_presenter(teaching):
    r, _ = teaching
    assert r["presenter"] and r["display"] == list(WINDOW)
    inner = r["inner"]
    for label in ("Step mode", "ambient estimate", "patch grid", "Shoot next patch", "Play"):
        x0, y0, x1, y1 = r["rects"][label]
        assert inner[0] - 1 <= x0 and x1 <= inner[2] + 1, (label, r["rects"][label], inner)
        assert inner[1] - 1 <= y0 and y1 <= inner[3] + 1, (label, r["rects"][label], inner)


def test_each_shot_spreads_light_only_with_the_ambient_estimate_off(teaching):
    r, _ = teaching
    off, on = r["shot1_off"], r["shot1_on"]
    assert off["shots"] == 1 and on["shots"] == 1 and off["shooter"] == on["shooter"]
    # unseen by the shooter: black without the estimate, rho * ambient with it
    assert off["dark_count"] >= 20 and off["dark_max"] == 0.0
    np.testing.assert_allclose(on["dark_B"], on["dark_expected"], rtol=1e-6)
    assert min(on["dark_B"]) > 0.0
    assert r["shot2"]["shots"] == 2 and r["shot2"]["shooter"] != off["shooter"]
    assert r["shot2"]["lit"] > off["lit"]                 # the second shot lit more patches


def test_the_shooting_patch_is_outlined_on_top(teaching):
    """In the captured window, the middle of each edge of the shooter's outline (projected
    with the viewport's camera) is the outline's yellow, and the black halo is just outside."""
    r, tmp = teaching
    from PIL import Image

    image = np.asarray(Image.open(tmp / "shot1_off.png").convert("RGB")).astype(int)
    points = np.asarray(r["outline"])
    assert points.shape == (4, 2)
    for k in range(4):
        a, b = points[k], points[(k + 1) % 4]
        x, y = np.round((a + b) / 2).astype(int)
        rgb = image[y, x]
        assert rgb[0] > 200 and rgb[1] > 180 and rgb[2] < 90, (k, (x, y), rgb.tolist())


def test_the_window_shows_the_solvers_rows_and_labels_the_faces(teaching):
    r, _ = teaching
    hv = r["hemicube"]
    assert hv["source_is_solver"] and hv["patch"] == hv["shooter"] == hv["slider"]
    # the window's F row of the patch is the solver's row of it (the same numbers)
    assert hv["row_equal"] and hv["row_sum"] > 0.5
    # the hemicube it pictures gives that row: same method, same resolution (atlas slot 1e-4)
    assert hv["picture_row_diff"] < 1e-4
    assert "hemicube 128x128, the rows the solver shot with" in hv["method"]
    labels = [t for t, *_ in hv["labels"]]
    assert labels[:5] == ["top", "left", "back", "right", "front"]
    assert len(labels) == 10     # and the five faces' sums on the weighted cross
    sums = [float(t) for t in labels[5:]]
    assert sum(sums) == pytest.approx(hv["total"], abs=3e-3)
    for _, x0, y0, x1, y1 in hv["labels"]:     # every label inside its image
        assert x1 - x0 > 4 and y1 - y0 > 4


def test_idle_frames_do_no_work_over_the_patches(teaching):
    """Once converged, 20 frames draw the slide without redrawing the radiosity triangles or
    rebuilding the heat map; a camera move redraws them."""
    idle = teaching[0]["idle"]
    assert idle["frames"] >= 20 and idle["redraws"] == 0 and not idle["matrix_rebuilt"]
    assert idle["redraws_after_camera_move"] >= 1


def test_play_converges_below_one_percent_unshot(teaching):
    r, _ = teaching
    done = r["played"]
    assert done["done"] and done["unshot"] < 0.01
    assert 10 < done["rows_known"] <= done["patches"] < done["shots"]


# ---------------------------------------------------------------- scenario side


def _rect(ctx, ref: str) -> list[float]:
    rect = ctx.item_info(ref).rect_full
    return [rect.min.x, rect.min.y, rect.max.x, rect.max.y]


def _shot(ctx, state, pv, shots: int) -> dict:
    assert _wait(ctx, lambda: pv.stats.get("shots") == shots and pv.soup is not None, 1500), \
        pv.message
    ctx.yield_(3)
    return dict(pv.stats)


def _dark(state, stats) -> tuple[np.ndarray, np.ndarray]:
    """Patches the shooter does not see (its row of F is 0) and that emit nothing."""
    from shadelab.pipelines.radiosity import _reflectance
    from shadelab.ui import pipelines

    pv = pipelines.view_of(state)
    i = stats["shooter_index"]
    row = pv.runner.rows[i]
    from shadelab.radiosity.patches import uniform_patches

    patches = uniform_patches(pv.job_scene, pv.job_scene.radiosity.patches)
    rho, emission = _reflectance(pv.job_scene, patches)
    dark = (row == 0.0) & (emission.max(axis=1) == 0.0)
    return dark, rho


def scenario_teaching(ctx, state, out: dict) -> None:
    from imgui_bundle import imgui

    from shadelab.lab.lesson import LessonRun, go_to, load_lesson
    from shadelab.ui import pipeline_viewport, pipelines
    from shadelab.ui import radiosity_view as rv

    state.view.presenter = True
    lesson = load_lesson("phong-to-radiosity")
    index = [k for k, s in enumerate(lesson.steps) if s.pipeline == "radiosity"][0]
    state.walk.lesson = LessonRun(lesson)
    go_to(state, index)
    ctx.yield_(5)
    out["presenter"] = bool(state.view.presenter)
    out["display"] = [int(imgui.get_io().display_size.x), int(imgui.get_io().display_size.y)]
    out["step"] = {"patches_grid": bool(state.view.radiosity_patches),
                   "ambient": bool(state.scene.radiosity.ambient),
                   "form_factors": state.scene.radiosity.form_factors,
                   "pipeline": pipelines.current(state),
                   "gizmos_hidden": pipeline_viewport.hides_gizmos(state)}
    pv = pipelines.view_of(state)
    ctx.window_focus(f"//{PANEL}")
    ctx.yield_(3)
    ctx.set_ref(f"//{PANEL}")
    rects = {"Step mode": _rect(ctx, "Step mode"), "ambient estimate":
             _rect(ctx, "ambient estimate"), "patch grid": _rect(ctx, "patch grid")}
    ctx.item_click("Step mode")
    ctx.yield_(3)
    rects["Shoot next patch"] = _rect(ctx, "Shoot next patch")
    rects["Play"] = _rect(ctx, "Play")
    inner = ctx.get_window_by_ref(f"//{PANEL}").inner_clip_rect
    out["inner"] = [inner.min.x, inner.min.y, inner.max.x, inner.max.y]
    out["rects"] = rects
    # shot 1, ambient off
    stats = _shot(ctx, state, pv, 1)
    dark, rho = _dark(state, stats)
    B = stats["B"]
    lit = int((B.max(axis=1) > 0).sum())
    out["shot1_off"] = {"shots": stats["shots"], "shooter": stats["shooter_index"],
                        "dark_count": int(dark.sum()), "dark_max": float(B[dark].max()),
                        "lit": lit}
    size = state.view.viewport_size
    outline = pipelines.shooter_outline(state.scene, size, stats["shooter"])
    origin = ctx.item_info("//Viewport/viewport_input").rect_full.min
    out["outline"] = (outline + np.array([origin.x, origin.y])).tolist()
    capture(ctx, str(Path(OUT_DIR) / "shot1_off.png"))
    # the window: the shooter's hemicube, the solver's row of F
    assert _wait(ctx, lambda: rv.view_of(state).shown == (rv.view_of(state).key,
                                                          stats["shooter_index"]), 300)
    ctx.yield_(3)
    view = rv.view_of(state)
    i = view.patch
    hv = view.views[i]
    solver_row = pv.runner.rows[i]
    out["hemicube"] = {
        "source_is_solver": view.source == id(pv.runner.rows), "patch": i,
        "shooter": stats["shooter_index"], "slider": view.patch,
        "row_equal": bool(view.known[i] and np.array_equal(view.F[i], solver_row)),
        "row_sum": float(view.F[i].sum()),
        "picture_row_diff": float(np.abs(hv["row"] - solver_row).max()),
        "method": rv.method_line(view, rv.solver_rows(state, view)),
        "labels": [list(x) for x in view.label_rects], "total": hv["total"]}
    capture(ctx, str(Path(OUT_DIR) / "hemicube_panel.png"))
    # shot 2
    ctx.item_click("Shoot next patch")
    stats2 = _shot(ctx, state, pv, 2)
    out["shot2"] = {"shots": stats2["shots"], "shooter": stats2["shooter_index"],
                    "lit": int((stats2["B"].max(axis=1) > 0).sum())}
    capture(ctx, str(Path(OUT_DIR) / "shot2_off.png"))
    # the ambient estimate on: the job starts again (the form factors kept), still stepping
    ctx.item_check("ambient estimate")
    ctx.yield_(2)
    assert _wait(ctx, lambda: pv.stats.get("ambient_shown") is True
                 and pv.stats.get("shots") == 1, 1500), pv.message
    ctx.yield_(3)
    on = dict(pv.stats)
    dark_on, rho_on = _dark(state, on)
    out["shot1_on"] = {"shots": on["shots"], "shooter": on["shooter_index"],
                       "dark_B": on["B"][dark_on].ravel().tolist(),
                       "dark_expected": (rho_on[dark_on] * on["ambient"]).ravel().tolist()}
    capture(ctx, str(Path(OUT_DIR) / "shot1_on.png"))
    # play: the shots stream to 1 % unshot energy
    ctx.item_uncheck("ambient estimate")
    ctx.yield_(2)
    ctx.item_click("Play")
    assert _wait(ctx, lambda: pv.stats.get("done") and pv.history.get("unshot"), 6000), \
        pv.message
    ctx.yield_(5)
    out["played"] = {"done": bool(pv.stats["done"]), "unshot": pv.history["unshot"][-1],
                     "rows_known": len(pv.runner.rows), "patches": pv.stats["patches"],
                     "shots": pv.stats["shots"]}
    capture(ctx, str(Path(OUT_DIR) / "converged.png"))
    # idle frames of the slide: no redraw of the patches' triangles, no heat-map rebuild
    from shadelab.ui.viewport import Viewport

    calls = []
    original = Viewport.draw_colored_triangles

    def counted(self, *args, **kwargs):
        calls.append(1)
        return original(self, *args, **kwargs)

    Viewport.draw_colored_triangles = counted
    try:
        # the heat map's data catches up with the last rows at most MATRIX_EVERY_S after they
        # arrive (a throttle, not idle work): idle is measured once it has
        view = rv.view_of(state)
        assert _wait(ctx, lambda: view.matrix is not None
                     and view.matrix["version"] == view.f_version, 600)
        ctx.yield_(2)
        built = view.matrix["at"]
        frame = state.frame
        ctx.yield_(20)
        out["idle"] = {"frames": state.frame - frame, "redraws": len(calls),
                       "matrix_rebuilt": rv.view_of(state).matrix["at"] != built}
        state.scene.camera.eye = tuple(np.add(state.scene.camera.eye, (5.0, 0.0, 0.0)))
        state.mark_edited()
        ctx.yield_(3)
        out["idle"]["redraws_after_camera_move"] = len(calls)
    finally:
        Viewport.draw_colored_triangles = original
    ctx.scroll_to_y(f"//{PANEL}", 330.0)     # the convergence plot and the matrix
    ctx.yield_(4)
    capture(ctx, str(Path(OUT_DIR) / "converged_plots.png"))
    ctx.scroll_to_bottom(f"//{PANEL}")
    ctx.yield_(4)
    capture(ctx, str(Path(OUT_DIR) / "converged_matrix.png"))


OUT_DIR = "."


def _main(name: str, out_dir: str) -> int:
    global OUT_DIR
    OUT_DIR = out_dir
    return run_scenario_main(globals(), name, out_dir, "cornell", WINDOW, autosave=False)


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1], sys.argv[2]))
