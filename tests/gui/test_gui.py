"""GUI tests: the real viewer under Xvfb, driven by ImGui Test Engine (immapp.testing).

Each scenario runs in its own process (a fresh GLFW window and GL context) on one Xvfb server
started for this module; the scenario writes what it measured to a JSON file, and the pytest
side asserts on it. Skipped, with the reason, when Xvfb is not installed.

Run one scenario by hand:  xvfb-run -a python3 tests/gui/test_gui.py kd_slider /tmp/out
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/: gui_harness
from gui_harness import capture, private_xvfb, run_scenario_main  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
WINDOW = (1280, 720)
SCENARIO_TIMEOUT = 90  # seconds per scenario process

pytestmark = pytest.mark.gui


# ---------------------------------------------------------------- pytest side


@pytest.fixture(scope="module")
def xdisplay():
    """A private Xvfb server for this module; yields its DISPLAY string."""
    yield from private_xvfb(f"{WINDOW[0] + 64}x{WINDOW[1] + 64}x24")


def run_scenario(name: str, display: str, tmp_path: Path, script: str = __file__,
                 timeout: float = SCENARIO_TIMEOUT) -> dict:
    """Run ``script NAME OUTDIR`` (a scenario under the ImGui Test Engine) on ``display``."""
    env = dict(os.environ, DISPLAY=display, XDG_STATE_HOME=str(tmp_path / "state"),
               PYTHONPATH=str(ROOT / "app"))
    for key in ("WAYLAND_DISPLAY", "PYOPENGL_PLATFORM"):
        env.pop(key, None)
    proc = subprocess.run([sys.executable, str(Path(script).resolve()), name, str(tmp_path)],
                          env=env, cwd=str(tmp_path), capture_output=True, text=True,
                          timeout=timeout)
    assert proc.returncode == 0, f"scenario {name} failed:\n{proc.stdout[-4000:]}\n" \
                                 f"{proc.stderr[-4000:]}"
    return json.loads((tmp_path / f"{name}.json").read_text())


def test_kd_slider_changes_the_pixel_as_the_reference_predicts(xdisplay, tmp_path):
    r = run_scenario("kd_slider", xdisplay, tmp_path)
    assert r["kd_after"] == pytest.approx(0.5, abs=1e-6)
    before, after = np.array(r["gpu_before"]), np.array(r["gpu_after"])
    # Cornell white is purely diffuse (ka = ks = 0): halving kd halves the pixel.
    np.testing.assert_allclose(after, 0.5 * before, rtol=1e-4)
    np.testing.assert_allclose(after, r["reference_after"], rtol=1e-4, atol=1e-6)
    assert r["undo_kd"] == 1.0 and r["redo_kd"] == 0.5
    assert r["uploads_before"] == r["uploads_after"]  # a coefficient re-uploads no geometry
    assert r["two_lights"] == [2, 2] and r["light_off"] == [2, 1]
    np.testing.assert_allclose(r["two_lights_gpu"], r["two_lights_reference"], rtol=1e-4,
                               atol=1e-6)
    np.testing.assert_allclose(r["light_off_gpu"], r["gpu_after"], rtol=1e-5)  # back to one
    assert np.max(r["two_lights_gpu"]) > np.max(r["gpu_after"])  # the new light adds light
    assert r["screenshots"] == ["shadelab-cornell-001.png"]
    from PIL import Image

    shot = np.asarray(Image.open(tmp_path / r["screenshots"][0]))
    h, w = r["viewport"][1], r["viewport"][0]
    assert shot.shape[1:] == (w, 3) and shot.shape[0] > h + 20  # the legend in a margin
    band = shot[h:, :200].astype(int)
    assert (band > 200).any() and (band < 60).any()  # white legend text on the dark margin
    assert r["toast"].startswith("saved ") and r["toast"].endswith(r["screenshots"][0])


def test_three_shading_modes_by_key_and_button(xdisplay, tmp_path):
    r = run_scenario("shading_modes", xdisplay, tmp_path)
    assert r["modes"] == ["flat", "gouraud", "phong", "flat", "blinn"]
    for gpu, ref in zip(r["gpu"], r["reference"], strict=True):
        np.testing.assert_allclose(gpu, ref, rtol=1e-4, atol=1e-6)
    flat, gouraud, phong = (np.array(v) for v in r["gpu"][:3])
    assert np.abs(flat - phong).max() > 1e-3 and np.abs(gouraud - phong).max() > 1e-4


def test_click_probes_the_pixel_and_lists_terms_that_add_up(xdisplay, tmp_path):
    r = run_scenario("probe_click", xdisplay, tmp_path)
    x, y = r["pixel"]
    w, h = r["viewport"]
    assert abs(x - w / 2) <= 2 and abs(y - h / 2) <= 2   # the click landed mid-viewport
    np.testing.assert_allclose(r["gpu"], r["reference"], rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(r["sum_of_terms"], r["reference"], rtol=1e-9)
    assert r["arrows"] >= 4 and r["material"] == "white"
    assert r["camera_moved"] and r["camera_reset"]
    assert r["touch_probed"] and r["touch_camera_kept"]
    tx, ty = r["touch_pixel"]
    assert abs(tx - 0.25 * w) <= 2 and abs(ty - 0.75 * h) <= 2


def test_save_reload_broken_file_and_autosave(xdisplay, tmp_path):
    r = run_scenario("save_reload", xdisplay, tmp_path)
    assert r["saved_kd"] == 0.25 and r["reloaded_kd"] == 0.25
    assert r["title_dirty"].endswith("*") and not r["title_saved"].endswith("*")
    assert "bad.toml" in r["broken_error"] and r["kd_after_broken"] == 0.25
    from shadelab.lab.session import load_session

    autosaved = load_session()  # the scenario's state folder (conftest: tmp_path / "state")
    assert autosaved.note == "" and autosaved.scene.materials["white"].kd == 0.25


def test_start_and_cancel_a_job_while_the_ui_keeps_drawing(xdisplay, tmp_path):
    r = run_scenario("jobs", xdisplay, tmp_path)
    assert r["cancelled"] and r["cancel_fraction"] < 1.0
    assert r["frames_while_running"] >= 10      # the UI drew frames while the job worked
    assert r["cancel_latency_s"] < 2.0       # 10 ms chunks: well before the 4 s job ends
    assert r["reference_done"] and r["reference_rmse"] < 1e-4
    assert r["reference_flip"] is not None and r["reference_flip"] < 1e-3  # FLIP shown too


def test_every_panel_and_shortcut_without_errors(xdisplay, tmp_path):
    r = run_scenario("smoke", xdisplay, tmp_path)
    assert r["light"] == ["spot", "lecture", 2.0]
    assert r["segments"] == 4 and r["uploaded_keys_changed"] == [0]  # only the floor re-uploaded
    assert r["toggles"] == {"compare": True, "diff_enabled": True, "show_wireframe": True,
                            "show_normals": True, "presenter": True, "show_help": True}
    assert r["after_toggles"] == {k: False for k in r["toggles"]}
    np.testing.assert_allclose(r["spot_gpu"], r["spot_reference"], rtol=1e-4, atol=1e-6)


# ---------------------------------------------------------------- scenario side (subprocess)


def _wait(ctx, until, frames: int = 600) -> bool:
    for _ in range(frames):
        if until():
            return True
        ctx.yield_()
    return until()


def _probe_at(ctx, state, pixel) -> None:
    state.probe.pixel, state.probe.result, state.probe.requested = tuple(pixel), None, True
    _wait(ctx, lambda: state.probe.result is not None and not state.probe.requested)


def _gl_side():
    """The running viewer's Viewport (GL internals; the state holds no GL object)."""
    from shadelab.ui.app import running_viewer

    return running_viewer().viewport


def _centre(state) -> tuple[int, int]:
    w, h = state.view.viewport_size
    return w // 2, h // 2


def scenario_kd_slider(ctx, state, out: dict) -> None:
    ctx.yield_(3)
    _probe_at(ctx, state, _centre(state))  # the back wall: Cornell white
    out["gpu_before"] = state.probe.result.gpu.tolist()
    out["uploads_before"] = len(_gl_side().renderer._gpu)
    keys_before = [g.key for g in _gl_side().renderer._gpu.values()]
    ctx.set_ref("//Materials")
    ctx.window_focus("//Materials")
    ctx.item_input_value("material_white/white/kd", 0.5)
    ctx.yield_(3)
    _probe_at(ctx, state, _centre(state))
    out["kd_after"] = state.scene.materials["white"].kd
    out["gpu_after"] = state.probe.result.gpu.tolist()
    out["reference_after"] = state.probe.result.reference.tolist()
    out["uploads_after"] = len(_gl_side().renderer._gpu)
    assert keys_before == [g.key for g in _gl_side().renderer._gpu.values()]
    ctx.key_press(imgui_key("mod_ctrl") | imgui_key("z"))
    ctx.yield_(2)
    out["undo_kd"] = state.scene.materials["white"].kd
    ctx.key_press(imgui_key("mod_ctrl") | imgui_key("y"))
    ctx.yield_(2)
    out["redo_kd"] = state.scene.materials["white"].kd
    ctx.window_focus("//Lights")  # add a light, then switch it off again
    ctx.set_ref("//Lights")
    ctx.item_click("Add light")
    ctx.yield_(3)
    _probe_at(ctx, state, _centre(state))
    out["two_lights"] = [len(state.scene.lights), len(state.probe.result.terms.lights)]
    out["two_lights_gpu"] = state.probe.result.gpu.tolist()
    out["two_lights_reference"] = state.probe.result.reference.tolist()
    ctx.item_uncheck("light1/##on")
    ctx.yield_(3)
    _probe_at(ctx, state, _centre(state))
    out["light_off"] = [len(state.scene.lights), len(state.scene.active_lights())]
    out["light_off_gpu"] = state.probe.result.gpu.tolist()
    ctx.key_press(imgui_key("s"))  # viewport screenshot with the legend burned in
    ctx.yield_(3)
    out["screenshots"] = sorted(p.name for p in Path(OUT_DIR).glob("shadelab-*.png"))
    out["toast"] = state.toast[0]
    out["viewport"] = list(state.view.viewport_size)


def scenario_shading_modes(ctx, state, out: dict) -> None:
    ctx.yield_(3)
    out["modes"], out["gpu"], out["reference"] = [], [], []
    w, h = state.view.viewport_size
    pixel = (w // 2, int(h * 0.2))  # the ceiling

    def record(mode: str) -> None:
        _probe_at(ctx, state, pixel)
        out["modes"].append(mode)
        out["gpu"].append(state.probe.result.gpu.tolist())
        out["reference"].append(state.probe.result.reference.tolist())

    for key, mode in (("_1", "flat"), ("_2", "gouraud"), ("_3", "phong")):
        ctx.key_press(imgui_key(key))
        ctx.yield_(2)
        assert state.scene.render.shading == mode, state.scene.render.shading
        record(mode)
    ctx.set_ref("//Scene")
    ctx.window_focus("//Scene")
    ctx.item_click("Flat")
    ctx.yield_(2)
    assert state.scene.render.shading == "flat"
    record("flat")
    state.scene.materials["white"].ks = 0.5
    ctx.key_press(imgui_key("b"))
    ctx.yield_(2)
    assert state.scene.render.specular == "blinn"
    record("blinn")


def scenario_probe_click(ctx, state, out: dict) -> None:
    ctx.yield_(3)
    ctx.set_ref("//Viewport")
    ctx.item_click("viewport_input")
    ok = _wait(ctx, lambda: state.probe.result is not None and not state.probe.requested)
    assert ok, "the click did not probe"
    p = state.probe.result
    out["pixel"], out["viewport"] = list(p.pixel), list(state.view.viewport_size)
    out["gpu"], out["reference"] = p.gpu.tolist(), p.reference.tolist()
    terms = p.terms
    total = terms.emission + terms.ambient + sum(t.diffuse + t.specular for t in terms.lights)
    out["sum_of_terms"] = total.tolist()
    out["material"] = p.hit.mesh.material
    from shadelab.lab import overlays

    out["arrows"] = len(overlays.probe_arrows(p, 1.0)) // 10  # 5 segments (10 ends) each
    capture(ctx, str(Path(OUT_DIR) / "probe.png"))
    eye = state.scene.camera.eye
    ctx.item_drag_with_delta("viewport_input", imgui_vec(60, 20))
    ctx.yield_(2)
    out["camera_moved"] = state.scene.camera.eye != eye
    ctx.key_press(imgui_key("r"))
    ctx.yield_(2)
    out["camera_reset"] = tuple(state.scene.camera.eye) == tuple(eye)
    # a touch-style press: the pointer lands a quarter of the way in with no move between,
    # then goes down and up in place: a probe of that pixel, the camera untouched
    rect = ctx.item_info("viewport_input").rect_full
    w, h = rect.max.x - rect.min.x, rect.max.y - rect.min.y
    ctx.mouse_teleport_to_pos(imgui_vec(rect.min.x + 0.25 * w, rect.min.y + 0.75 * h))
    state.probe.result = None
    ctx.mouse_down(0)
    ctx.mouse_up(0)
    ok = _wait(ctx, lambda: state.probe.result is not None and not state.probe.requested)
    out["touch_probed"] = ok
    out["touch_pixel"] = list(state.probe.result.pixel) if ok else None
    out["touch_camera_kept"] = tuple(state.scene.camera.eye) == tuple(eye)


def scenario_save_reload(ctx, state, out: dict) -> None:
    ctx.yield_(3)
    target = str(Path(OUT_DIR) / "mine.toml")
    ctx.window_focus("//Materials")
    ctx.set_ref("//Materials")
    ctx.item_input_value("material_white/white/kd", 0.25)
    ctx.yield_(3)
    out["title_dirty"] = state.title()
    ctx.window_focus("//Scene")
    ctx.set_ref("//Scene")
    ctx.item_input_value("File", target)
    ctx.item_click("Save to file")
    ctx.yield_(2)
    out["saved_kd"] = state.scene.materials["white"].kd
    out["title_saved"] = state.title()
    state.scene.materials["white"].kd = 0.9
    state.mark_edited()
    ctx.yield_(2)
    ctx.item_click("Open file")
    ctx.yield_(2)  # unsaved edits: the viewer asks first
    ctx.item_click("//Discard unsaved changes?/Open (discard)")
    ctx.yield_(2)
    ctx.set_ref("//Scene")
    out["reloaded_kd"] = state.scene.materials["white"].kd
    bad = Path(OUT_DIR) / "bad.toml"
    bad.write_text("schema_version = 1\n[materials.white]\nkd = 'lots'\n")
    ctx.item_input_value("File", str(bad))
    ctx.item_click("Open file")
    ctx.yield_(2)
    out["broken_error"] = state.error
    out["kd_after_broken"] = state.scene.materials["white"].kd
    ctx.yield_(5)


def scenario_jobs(ctx, state, out: dict) -> None:
    import threading

    from shadelab.lab.jobs import JobKind, available_jobs
    from shadelab.progress import Progress

    closed = threading.Event()

    def slow(scene, size):
        try:
            for i in range(400):
                time.sleep(0.01)
                yield Progress(np.zeros((size[1], size[0], 3), np.float32), (i + 1) / 400)
        finally:
            closed.set()

    state.offline.kinds = [JobKind("Slow test job", slow)] + available_jobs()
    ctx.yield_(2)
    ctx.window_focus("//Offline render")
    ctx.set_ref("//Offline render")
    ctx.item_click("Start")
    _wait(ctx, lambda: state.offline.runner.running)
    frame0 = state.frame
    ctx.yield_(20)
    out["frames_while_running"] = state.frame - frame0
    ctx.item_click("Cancel")
    _wait(ctx, lambda: not state.offline.runner.running)
    out["cancel_latency_s"] = state.offline.runner.finished - state.offline.runner.cancel_requested
    out["cancelled"] = bool(state.offline.runner.cancelled and closed.is_set())
    out["cancel_fraction"] = state.offline.runner.snapshot()[0].fraction
    state.offline.kind = 1  # the numpy reference raster
    state.offline.size = 64
    ctx.yield_(2)
    ctx.item_click("Start")
    _wait(ctx, lambda: state.offline.runner.started and not state.offline.runner.running, 2000)
    # the UI may have compared a partial image first: wait until the final one is uploaded
    _wait(ctx, lambda: state.offline.comparison is not None
          and state.offline.version == state.offline.runner.snapshot()[1])
    out["reference_done"] = state.offline.runner.snapshot()[0].fraction == 1.0
    out["reference_rmse"] = state.offline.comparison["rmse"]
    out["reference_flip"] = state.offline.comparison.get("flip")


def scenario_smoke(ctx, state, out: dict) -> None:
    """Drive every panel once (spot light, lecture attenuation, tessellation, toggles)."""
    ctx.yield_(3)
    ctx.window_focus("//Lights")
    ctx.yield_(3)  # the tab comes to the front
    ctx.set_ref("//Lights/light0/###node")  # combo_click splits its ref at the first '/'
    ctx.combo_click("kind/spot")
    ctx.yield_(2)
    ctx.combo_click("attenuation/lecture")
    ctx.yield_(2)
    ctx.item_input_value("c1", 2.0)
    ctx.yield_(3)
    light = state.scene.lights[0]
    out["light"] = [light.kind, light.attenuation, light.c1]
    w, h = state.view.viewport_size
    _probe_at(ctx, state, (w // 2, int(h * 0.85)))
    out["spot_gpu"], out["spot_reference"] = state.probe.result.gpu.tolist(), \
        state.probe.result.reference.tolist()
    keys = {i: g.key for i, g in _gl_side().renderer._gpu.items()}
    ctx.window_focus("//Objects")
    ctx.yield_(3)
    ctx.set_ref("//Objects")
    ctx.item_open("object0/###obj")
    ctx.item_input_value("object0/###obj/tessellation (segments)", 4)
    ctx.yield_(3)
    out["segments"] = state.scene.objects[0].segments
    out["uploaded_keys_changed"] = [i for i, g in _gl_side().renderer._gpu.items()
                                    if keys.get(i) != g.key]
    toggles = {"compare": "c", "diff_enabled": "d", "show_wireframe": "w",
               "show_normals": "n", "presenter": "f", "show_help": "h"}
    for key in toggles.values():
        ctx.key_press(imgui_key(key))
        ctx.yield_(2)
    out["toggles"] = {name: getattr(state.view, name) for name in toggles}
    for key in toggles.values():
        ctx.key_press(imgui_key(key))
        ctx.yield_(2)
    out["after_toggles"] = {name: getattr(state.view, name) for name in toggles}


OUT_DIR = "."


def imgui_key(name: str):
    from imgui_bundle import imgui

    return int(getattr(imgui.Key, name))  # a plain int: chords OR on every Python 3.11


def imgui_vec(x: float, y: float):
    from imgui_bundle import imgui

    return imgui.ImVec2(x, y)


def _main(name: str, out_dir: str) -> int:
    global OUT_DIR
    OUT_DIR = out_dir
    return run_scenario_main(globals(), name, out_dir, "cornell", WINDOW)


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1], sys.argv[2]))
