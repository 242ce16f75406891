"""GUI tests (issue 11): object translate / rotate / scale in the Objects panel move the
object's pixels by what the camera predicts and undo in one step; presenter mode at
3840x2160 cuts no widget off (where Xvfb can make a 4K screen).

Each scenario runs in its own process under a private Xvfb. Run one by hand:
    xvfb-run -s "-screen 0 1344x784x24" python3 tests/gui/test_gui_transforms.py translate /tmp/out
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_gui import run_scenario, xdisplay  # noqa: E402,F401  (the module's Xvfb fixture)

from gui_harness import private_xvfb, run_scenario_main  # noqa: E402

pytestmark = pytest.mark.gui
SIZES = {"translate": (1280, 720), "layout_3840": (3840, 2160)}
MOVE_X = 0.8      # world units the sphere is moved along +x
SCALE = 1.5       # and then scaled by


def _run(name, display, tmp_path):
    return run_scenario(name, display, tmp_path, script=__file__, timeout=240)


def test_translate_and_scale_in_the_objects_panel_move_the_pixels(xdisplay, tmp_path):  # noqa: F811
    r = _run("translate", xdisplay, tmp_path)
    assert r["translate"] == pytest.approx([MOVE_X, 0.0, 0.0])
    # The sphere sits at the camera's target: MOVE_X world units there are this many pixels.
    expected = MOVE_X / r["pixel_size"]
    assert expected > 50
    shift = r["centroid_after"][0] - r["centroid_before"][0]
    assert shift == pytest.approx(expected, rel=0.03)
    assert abs(r["centroid_after"][1] - r["centroid_before"][1]) < 1.0
    assert r["area_after"] == pytest.approx(r["area_before"], rel=0.05)
    # One drag / typed value is one undo step; undo puts the pixels back.
    assert r["undo_steps"] == 1
    assert r["undone_translate"] == [0.0, 0.0, 0.0]
    assert np.allclose(r["centroid_undone"], r["centroid_before"], atol=0.5)
    # Scale 1.5 on every axis: the silhouette's width grows 1.5 times (perspective: about).
    assert r["scale"] == pytest.approx([SCALE] * 3)
    assert r["width_scaled"] / r["width_before"] == pytest.approx(SCALE, rel=0.06)
    assert r["errors"] == ""


@pytest.fixture(scope="module")
def display_4k():
    """A private 4K Xvfb screen (skipped when Xvfb cannot make one)."""
    yield from private_xvfb("3904x2224x24", failed="Xvfb could not make a 3904x2224 screen")


def test_presenter_layout_at_3840x2160_cuts_nothing_off(display_4k, tmp_path):
    from test_gui_presenter import DOCK_WINDOWS

    r = _run("layout_3840", display_4k, tmp_path)
    assert r["display"] == list(SIZES["layout_3840"])
    assert set(r["checked"]) == set(DOCK_WINDOWS)
    for label in DOCK_WINDOWS:
        if label != "Equation & probe":  # its text and table rows carry no item ids
            assert r["checked"][label] >= 3, f"{label}: too few items seen"
    assert r["clipped"] == [], f"items past their window's right edge: {r['clipped'][:8]}"
    assert r["hidden_visible"] == []
    assert r["presenter_viewport"][0] >= SIZES["layout_3840"][0] - 2


# ---------------------------------------------------------------- scenario side


OUT_DIR = "."


def _viewport_image(ctx, state, name: str) -> np.ndarray:
    """The viewport's displayed image (sRGB8), saved by the viewer's own screenshot path
    (GL is read on the GUI thread; the test body runs on the engine's thread)."""
    from PIL import Image

    path = Path(OUT_DIR) / f"{name}.png"
    state.view.legend_in_screenshot = False
    state.screenshot_requested = str(path)
    for _ in range(100):
        ctx.yield_()
        if not state.screenshot_requested and path.is_file():
            break
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.int32)


def _mask_stats(image: np.ndarray) -> dict:
    """Centroid (x, y), area and width of the pixels that are not the black background."""
    mask = image.max(axis=2) > 8
    ys, xs = np.nonzero(mask)
    return {"centroid": [float(xs.mean()), float(ys.mean())], "area": int(mask.sum()),
            "width": int(xs.max() - xs.min() + 1)}


def _one_sphere(state) -> None:
    from shadelab.scene.model import Object

    scene = state.scene
    material = next(iter(scene.materials))
    scene.objects = [Object(shape="sphere", name="ball", material=material, radius=0.4,
                            subdivisions=4)]
    scene.camera.eye, scene.camera.target = (0.0, 0.0, 6.0), (0.0, 0.0, 0.0)
    scene.camera.up = (0.0, 1.0, 0.0)
    scene.render.background = (0.0, 0.0, 0.0)
    scene.render.shadows = "none"
    state.view.show_fps, state.view.show_gizmos = False, False
    state.mark_edited()


def scenario_translate(ctx, state, out: dict) -> None:
    from imgui_bundle import imgui

    from shadelab.ui import gizmos

    _one_sphere(state)
    ctx.yield_(6)
    state.commit_edit()
    ctx.yield_(2)
    before = _mask_stats(_viewport_image(ctx, state, "before"))
    from shadelab.ui.app import running_viewer

    width, height = running_viewer().viewport.panes["main"].size
    out["pixel_size"] = gizmos.pixel_size_at(state, (0.0, 0.0, 0.0), height, width)
    ctx.window_focus("//Objects")
    ctx.set_ref("//Objects")
    ctx.item_open("object0/###obj")
    ctx.yield_(2)
    steps_before = state.history.index
    ctx.item_input_value("object0/###obj/translate/$$0", MOVE_X)
    ctx.yield_(6)
    after = _mask_stats(_viewport_image(ctx, state, "after"))
    out["translate"] = list(state.scene.objects[0].translate)
    out["undo_steps"] = state.history.index - steps_before
    ctx.key_press(int(imgui.Key.mod_ctrl) | int(imgui.Key.z))
    ctx.yield_(6)
    out["undone_translate"] = list(state.scene.objects[0].translate)
    undone = _mask_stats(_viewport_image(ctx, state, "undone"))
    for k in range(3):
        ctx.item_input_value(f"object0/###obj/scale/$${k}", SCALE)
        ctx.yield_(2)
    ctx.yield_(4)
    scaled = _mask_stats(_viewport_image(ctx, state, "scaled"))
    out["scale"] = list(state.scene.objects[0].scale)
    out.update(centroid_before=before["centroid"], centroid_after=after["centroid"],
               centroid_undone=undone["centroid"], area_before=before["area"],
               area_after=after["area"], width_before=before["width"],
               width_scaled=scaled["width"], errors=state.error)


def scenario_layout_3840(ctx, state, out: dict) -> None:
    from test_gui_presenter import _check_layout

    _check_layout(ctx, state, out)


def _main(name: str, out_dir: str) -> int:
    global OUT_DIR
    OUT_DIR = out_dir
    import test_gui_presenter

    test_gui_presenter.OUT_DIR = out_dir
    return run_scenario_main(globals(), name, out_dir, "lecture", SIZES[name], autosave=False)


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1], sys.argv[2]))
