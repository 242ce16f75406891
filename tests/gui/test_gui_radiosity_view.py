"""GUI tests of issue 10's leftovers, under Xvfb: the "Hemicube & F" window, filtered vs
interpolated transparency in the viewport against the formulas, and the raster pipelines'
viewport image against ``shadelab render --npy``.

Run one by hand:  xvfb-run -a python3 tests/gui/test_gui_radiosity_view.py hemicube_window /tmp/out
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_gui import _probe_at, _wait, run_scenario  # noqa: E402
from test_gui import xdisplay as _xdisplay_fixture  # noqa: E402

from gui_harness import gl_objects_in, run_scenario_main  # noqa: E402

xdisplay = _xdisplay_fixture    # the module's private Xvfb server (a pytest fixture)

ROOT = Path(__file__).resolve().parents[2]
WINDOW = (1280, 720)
TIMEOUT = 240
PATCHES = 120

pytestmark = pytest.mark.gui


def _run(name: str, display: str, tmp_path: Path) -> dict:
    return run_scenario(name, display, tmp_path, script=__file__, timeout=TIMEOUT)


# ---------------------------------------------------------------- pytest side


@pytest.mark.gl
def test_hemicube_window_shows_the_patch_and_F_while_the_frame_keeps_coming(xdisplay,
                                                                            tmp_path, gl_ctx):
    from shadelab.radiosity.formfactors import heatmap_data
    from shadelab.radiosity.patches import uniform_patches
    from shadelab.raster.hemicube import Hemicube
    from shadelab.scene import load_preset

    r = _run("hemicube_window", xdisplay, tmp_path)
    assert r["patch"] == 20 and r["n"] > 100
    F = np.load(tmp_path / "F.npy")
    # the heat map's data is F (the window's matrix), F the GPU hemicube's, to rasterization
    scene = load_preset("cornell")
    patches = uniform_patches(scene, PATCHES)
    cube = Hemicube(patches, scene.radiosity.hemicube_resolution, ctx=gl_ctx)
    try:
        fresh = cube.rows(np.arange(len(patches)))
    finally:
        cube.release()
    np.testing.assert_allclose(F, fresh, atol=1e-6)
    np.testing.assert_array_equal(r["row_sums"], heatmap_data(F)["row_sums"])
    # five faces' sums == the row sum of F (another atlas slot: 1e-4) and add up
    assert r["total"] == pytest.approx(F[20].sum(), abs=1e-4)
    assert r["total"] == pytest.approx(sum(r["face_sums"].values()), abs=1e-12)
    assert r["frames"] >= r["batches"]           # one batch of rows per frame, UI drawn
    assert r["textures"] == [[256, 256], [256, 256]]   # the 2 res cross, res 128
    assert r["gl_objects_in_state"] == []        # the GL side keeps the hemicube and textures
    assert r["follow_shooter"] == r["shooter"]   # the radiosity pipeline's shooting patch
    assert r["patch_id_soup"] == [6 * r["n"], 6]


def test_filtered_and_interpolated_transparency_match_the_formulas(xdisplay, tmp_path):
    """presets/transparency.toml, one pixel through the blue pane only and one through the
    green: I1 = the pane opaque (kt = 0), I2 = the pane removed. Interpolated:
    I = (1 - kt) I1 + kt I2; filtered: I = I1 + kt Ot I2; the Materials combo switches the
    blue pane to filtered and its pixel follows the other formula. Float target: 1e-4."""
    r = _run("transparency", xdisplay, tmp_path)
    for case in ("blue_interpolated", "green_filtered", "blue_filtered"):
        c = r[case]
        I1, I2, kt, Ot = (np.array(c[k]) for k in ("I1", "I2", "kt", "Ot"))
        expected = I1 + kt * Ot * I2 if c["model"] == "filtered" else (1 - kt) * I1 + kt * I2
        np.testing.assert_allclose(c["I"], expected, rtol=1e-4, atol=1e-5, err_msg=case)
    assert r["blue_filtered"]["model_after_combo"] == "filtered"
    # the two models differ on that pixel (the test can tell them apart)
    assert np.abs(np.array(r["blue_interpolated"]["I"])
                  - np.array(r["blue_filtered"]["I"])).max() > 1e-2


@pytest.mark.parametrize("name", ["gouraud", "phong", "painter"])
def test_raster_pipeline_switch_equals_the_cli_render(xdisplay, tmp_path, name):
    """The Pipeline combo's choice draws the same image as ``shadelab render --npy`` with its
    shading and visibility: the viewport's screenshot (what the pane shows, sRGB 8-bit, no
    legend) equals the CLI's linear image encoded the same way to 1 level (rounding)."""
    from PIL import Image

    from shadelab.shading.conventions import to_srgb8

    r = _run(f"raster_{name}", xdisplay, tmp_path)
    w, h = r["size"]
    viewport = np.asarray(Image.open(tmp_path / f"{name}.png")).astype(int)
    shading, visibility = r["render"]
    out = tmp_path / "cli.npy"
    proc = subprocess.run([sys.executable, "-m", "shadelab", "render", "cornell", "-o",
                           str(tmp_path / "cli.png"), "--size", f"{w}x{h}", "--shading",
                           shading, "--visibility", visibility, "--npy", str(out)],
                          capture_output=True, text=True, cwd=str(tmp_path),
                          env={**os.environ, "PYTHONPATH": str(ROOT / "app")})
    assert proc.returncode == 0, proc.stderr
    cli = to_srgb8(np.load(out), r["exposure"]).astype(int)
    assert viewport.shape == cli.shape
    diff = np.abs(viewport - cli)
    assert diff.max() <= 1, (diff.max(), np.mean(diff > 0))   # sRGB levels: rounding only


# ---------------------------------------------------------------- scenario side


def scenario_hemicube_window(ctx, state, out: dict) -> None:
    from shadelab.ui import pipelines
    from shadelab.ui import radiosity_view as rv

    state.scene.radiosity.patches = PATCHES
    state.mark_edited()
    frame0 = state.frame
    ctx.window_focus("//Hemicube & F")
    ctx.yield_(3)
    ctx.set_ref("//Hemicube & F")
    view = rv.view_of(state)
    assert _wait(ctx, lambda: view.patches is not None and view.rows_done >= len(view.patches),
                 600), view.error
    out["frames"] = state.frame - frame0
    out["n"] = n = len(view.patches)
    out["batches"] = -(-n // view.batch)
    ctx.item_input_value("patch", 20)
    assert _wait(ctx, lambda: view.shown == (view.key, 20), 60), view.error
    out["patch"] = view.patch
    hv = view.views[view.patch]
    out["total"], out["face_sums"] = hv["total"], hv["face_sums"]
    out["row_sums"] = view.F.sum(axis=1).tolist()
    np.save(Path(OUT_DIR) / "F.npy", view.F)
    out["textures"] = [list(state.gpu.texture(k).size) for k in ("hemicube_ids", "hemicube_dF")]
    out["gl_objects_in_state"] = gl_objects_in(state)
    from imgui_bundle import imgui
    from imgui_bundle.immapp import testing

    testing.capture(ctx, str(Path(OUT_DIR) / "hemicube_window.png"),
                    flags=imgui.test_engine.CaptureFlags_.hide_mouse_cursor)
    # follow the viewport's radiosity: the shown patch is the shooting one
    ctx.item_check("follow the shooting patch")
    ctx.item_check("patch-id view (viewport)")
    pipelines.set_pipeline(state, "radiosity")
    pv = pipelines.view_of(state)
    assert _wait(ctx, lambda: pv.stats.get("done") and pv.stats.get("shooter_index")
                 is not None, 3000), pv.message
    ctx.yield_(3)                # the last shooter stays: the window has followed it
    out["shooter"] = int(pv.stats["shooter_index"])
    out["follow_shooter"] = view.patch if view.follow else -1
    out["patch_id_soup"] = list(rv.viewport_soup(state, pv.soup).shape)
    ctx.yield_(5)
    testing.capture(ctx, str(Path(OUT_DIR) / "patch_ids.png"),
                    flags=imgui.test_engine.CaptureFlags_.hide_mouse_cursor)


def _pixel_of(state, point) -> tuple[int, int]:
    from shadelab.ui import pipelines

    xy, front = pipelines.project(state.scene, state.view.viewport_size, np.array([point]))
    assert front[0]
    return int(xy[0, 0]), int(xy[0, 1])


def _gpu(ctx, state, pixel) -> list:
    ctx.yield_(3)
    _probe_at(ctx, state, pixel)
    return state.probe.result.gpu.tolist()


def _case(ctx, state, material: str, obj_name: str, point) -> dict:
    scene = state.scene
    m = scene.materials[material]
    pixel = _pixel_of(state, point)
    case = {"model": m.transparency, "kt": m.kt, "Ot": list(m.Ot), "pixel": list(pixel)}
    case["I"] = _gpu(ctx, state, pixel)
    kt = m.kt
    m.kt = 0.0
    state.mark_edited()
    case["I1"] = _gpu(ctx, state, pixel)
    m.kt = kt
    objects = list(scene.objects)
    scene.objects = [o for o in objects if o.name != obj_name]
    state.mark_edited()
    case["I2"] = _gpu(ctx, state, pixel)
    scene.objects = objects
    state.mark_edited()
    ctx.yield_(3)
    return case


def scenario_transparency(ctx, state, out: dict) -> None:
    ctx.yield_(3)
    blue, green = (-1.4, 0.5, 0.5), (1.4, 0.8, 1.2)   # each seen through that pane only
    out["blue_interpolated"] = _case(ctx, state, "interpolated", "blue pane (interpolated)",
                                     blue)
    out["green_filtered"] = _case(ctx, state, "filtered", "green pane (filtered)", green)
    ctx.window_focus("//Materials")
    ctx.yield_(2)
    base = "material_interpolated/interpolated/transparency, reflection, emission"
    ctx.set_ref("//Materials")
    ctx.item_open(base)
    ctx.yield_(2)
    ctx.set_ref(f"//Materials/{base}")
    ctx.combo_click("transparency/filtered I1 + kt Ot I2")
    ctx.yield_(3)
    model = state.scene.materials["interpolated"].transparency
    out["blue_filtered"] = _case(ctx, state, "interpolated", "blue pane (interpolated)", blue)
    out["blue_filtered"]["model_after_combo"] = model


def _raster(ctx, state, out: dict, name: str) -> None:
    from shadelab.ui import pipelines

    ctx.yield_(3)
    ctx.window_focus("//Scene")
    ctx.yield_(2)
    ctx.set_ref("//Scene")
    ctx.combo_click(f"Pipeline/{pipelines.LABELS[name]}")
    ctx.yield_(6)
    out["render"] = [state.scene.render.shading, state.scene.render.visibility]
    out["exposure"], out["tonemap"] = state.scene.render.exposure, str(state.view.tonemap)
    # GL reads belong to the UI thread (this coroutine has no context): its screenshot
    path = Path(OUT_DIR) / f"{name}.png"
    state.view.legend_in_screenshot = False
    state.screenshot_requested = str(path)
    assert _wait(ctx, lambda: path.exists() and not state.screenshot_requested, 100)
    ctx.yield_(2)
    from PIL import Image

    image = np.asarray(Image.open(path))
    out["size"] = [image.shape[1], image.shape[0]]


def scenario_raster_gouraud(ctx, state, out: dict) -> None:
    _raster(ctx, state, out, "gouraud")


def scenario_raster_phong(ctx, state, out: dict) -> None:
    _raster(ctx, state, out, "phong")


def scenario_raster_painter(ctx, state, out: dict) -> None:
    _raster(ctx, state, out, "painter")


OUT_DIR = "."
PRESETS = {"transparency": "transparency"}


def _main(name: str, out_dir: str) -> int:
    global OUT_DIR
    OUT_DIR = out_dir
    return run_scenario_main(globals(), name, out_dir, PRESETS.get(name, "cornell"), WINDOW)


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1], sys.argv[2]))
