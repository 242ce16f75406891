"""GUI tests of the viewport pipelines and the Algorithms panel (issue 10), under Xvfb.

Each scenario drives the real viewer with ImGui Test Engine (see tests/gui/test_gui.py) and
writes what it measured to JSON; the pytest side asserts on it against closed forms, the
numpy reference or a fresh render of the same scene.

Run one by hand:  xvfb-run -a python3 tests/gui/test_gui_pipelines.py follow_edits /tmp/out
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_gui import _probe_at, _wait, imgui_key, run_scenario  # noqa: E402
from test_gui import xdisplay as _xdisplay_fixture  # noqa: E402

from gui_harness import run_scenario_main  # noqa: E402

xdisplay = _xdisplay_fixture    # the module's private Xvfb server (a pytest fixture)

ROOT = Path(__file__).resolve().parents[2]
WINDOW = (1280, 720)
TIMEOUT = 240

pytestmark = pytest.mark.gui


def _run(name: str, display: str, tmp_path: Path) -> dict:
    return run_scenario(name, display, tmp_path, script=__file__, timeout=TIMEOUT)


# ---------------------------------------------------------------- pytest side


def test_shadow_volumes_checkbox_darkens_the_shadowed_pixel_to_the_ambient_term(xdisplay,
                                                                               tmp_path):
    r = _run("shadows", xdisplay, tmp_path)
    assert r["shadows"] == "volumes" and r["S"] == 0.0
    before, after = np.array(r["gpu_before"]), np.array(r["gpu_after"])
    # S_i = 0: only Le + Ia ka Od is left (the reference with the shadow term), darker
    np.testing.assert_allclose(after, r["reference_after"], rtol=1e-4, atol=1e-6)
    assert np.all(after < before - 1e-3)
    assert r["undo_shadows"] == "none"       # the checkbox is an undoable scene edit
    assert r["method"] == "zpass"


def test_raytrace_pipeline_draws_the_cli_image_in_the_viewport(xdisplay, tmp_path):
    r = _run("raytrace_pipeline", xdisplay, tmp_path)
    w, h = r["size"]
    viewport = np.load(tmp_path / "viewport.npy")
    assert viewport.shape == (h, w, 3)
    # coarse first: the job published 1/8, 1/4, 1/2 and full resolution in that order ...
    assert r["levels_published"] == [8, 4, 2, 1]
    # ... and the viewport showed a subsequence of them (a loaded machine may skip a level
    # between two frames; the newest is always the one shown), ending at full resolution
    seen = r["levels_seen"]
    assert seen and seen[-1] == 1 and seen == sorted(seen, reverse=True)
    assert set(seen) <= {8, 4, 2, 1}
    out = tmp_path / "cli.npy"
    proc = subprocess.run([sys.executable, "-m", "shadelab", "raytrace", "cornell", "-o",
                           str(tmp_path / "cli.png"), "--size", f"{w}x{h}", "--npy", str(out)],
                          capture_output=True, text=True, cwd=str(tmp_path),
                          env={**__import__("os").environ, "PYTHONPATH": str(ROOT / "app")})
    assert proc.returncode == 0, proc.stderr
    cli = np.load(out)
    # the same tracer on the same scene: equal to float32 rounding
    np.testing.assert_allclose(viewport, cli, atol=1e-5)
    assert r["frames_while_refining"] >= 3       # the UI kept drawing


def test_kd_edit_restarts_the_raytrace_from_coarse_and_ends_at_a_fresh_render(xdisplay,
                                                                             tmp_path):
    r = _run("follow_edits", xdisplay, tmp_path)
    assert r["kd"] == 0.5 and r["jobs_after"] == r["jobs_before"] + 1
    assert r["frames_to_restart"] <= 5        # restarted at once (coarse first: see above)
    assert r["max_diff_vs_fresh"] < 1e-5
    assert r["max_diff_vs_before"] > 1e-2     # and the edit did change the image


def test_radiosity_resolve_keeps_the_form_factors_after_a_material_edit(xdisplay, tmp_path):
    r = _run("radiosity_resolve", xdisplay, tmp_path)
    assert r["patches_setting"] == 120
    assert r["first"]["form_factors_reused"] is False
    assert r["second"]["form_factors_reused"] is True
    assert r["second"]["ff_token"] == r["first"]["ff_token"]   # the same FormFactors object
    assert r["soup_shape"][1] == 6 and r["soup_shape"][0] > 0
    assert r["max_rel_diff_vs_fresh"] < 1e-9    # re-solve == solving the edited scene anew
    assert r["dimmer"]                            # kd 0.5 on white: the room got darker


def test_bad_input_is_refused_in_place_and_the_scene_is_unchanged(xdisplay, tmp_path):
    r = _run("bad_input", xdisplay, tmp_path)
    assert r["spp"] == 1 and "refused" in r["spp_message"] and "-4" in r["spp_message"]
    assert r["patches"] == r["patches_before"] and "refused" in r["patches_message"]
    assert r["path_spp"] == r["path_spp_before"] and "refused" in r["path_spp_message"]
    assert r["depth"] == 3                    # a valid value is taken
    assert not r["dirty_after_refusals"]


def test_pipeline_names_and_raster_choices(xdisplay, tmp_path):
    r = _run("raster_pipelines", xdisplay, tmp_path)
    assert r["gouraud"] == ["gouraud", "zbuffer"]
    assert r["painter"] == ["phong", "painter"]
    assert r["kr_follows"] == -1.0 and r["kr_set"] >= 0.0
    assert r["transparency"] == "filtered"


# ---------------------------------------------------------------- scenario side


def _open_algorithms(ctx) -> None:
    ctx.window_focus("//Algorithms")
    ctx.yield_(3)
    ctx.set_ref("//Algorithms")


def _wait_job_done(ctx, view, frames: int = 6000) -> bool:
    return _wait(ctx, lambda: view.runner is not None and view.wanted is None
                 and not view.runner.running and view.version >= 0
                 and view.stats.get("done"), frames)


def _blocked(state, point) -> bool:
    """Closed-form oracle of S_i: a ray from the point to the light hits something first."""
    from shadelab.raytrace.surface import TraceContext

    light = state.scene.lights[0]
    to_light = np.asarray(light.position, float) - np.asarray(point, float)
    distance = float(np.linalg.norm(to_light))
    d = to_light / distance
    o = np.asarray(point, float) + 1e-4 * distance * d
    hits = TraceContext(state.scene).accel.intersect(o[None], d[None])
    return bool(hits.hit[0] and hits.t[0] < distance * (1 - 1e-3))


def _shadowed_pixel(ctx, state):
    """A viewport pixel whose surface point the light cannot see (S = 0)."""
    w, h = state.view.viewport_size
    for fy in (0.75, 0.8, 0.85, 0.7, 0.9):
        for fx in (0.15, 0.2, 0.25, 0.1, 0.6, 0.65):
            _probe_at(ctx, state, (int(w * fx), int(h * fy)))
            p = state.probe.result
            if p is not None and _blocked(state, p.point):
                return (int(w * fx), int(h * fy))
    raise AssertionError("no shadowed pixel found")


def scenario_shadows(ctx, state, out: dict) -> None:
    ctx.yield_(3)
    pixel = _shadowed_pixel(ctx, state)
    out["gpu_before"] = state.probe.result.gpu.tolist()
    _open_algorithms(ctx)
    ctx.combo_click("shadows/shadow volumes")
    ctx.yield_(3)
    _probe_at(ctx, state, pixel)
    out["shadows"] = state.scene.render.shadows
    out["S"] = 0.0 if _blocked(state, state.probe.result.point) else 1.0
    out["gpu_after"] = state.probe.result.gpu.tolist()
    terms = state.probe.result.terms      # S_i = 0 leaves Le + Ia ka Od
    out["reference_after"] = (terms.emission + terms.ambient).tolist()
    ctx.combo_click("stencil counting/z-pass")
    ctx.yield_(3)
    out["method"] = state.scene.render.shadow_method
    ctx.key_press(imgui_key("mod_ctrl") | imgui_key("z"))
    ctx.yield_(2)
    ctx.key_press(imgui_key("mod_ctrl") | imgui_key("z"))
    ctx.yield_(2)
    out["undo_shadows"] = state.scene.render.shadows


def _choose_pipeline(ctx, label: str) -> None:
    ctx.window_focus("//Scene")
    ctx.yield_(2)
    ctx.set_ref("//Scene")
    ctx.combo_click(f"Pipeline/{label}")
    ctx.yield_(2)


def scenario_raytrace_pipeline(ctx, state, out: dict) -> None:
    from shadelab.ui import pipelines

    state.view.render_scale = 0.5
    ctx.yield_(3)
    _choose_pipeline(ctx, "ray tracing (Whitted)")
    view = pipelines.view_of(state)
    levels, frame0 = [], state.frame
    ok = _wait(ctx, lambda: (levels.append(view.stats.get("level"))
                             if view.stats.get("level") not in levels[-1:] else None,
                             view.stats.get("done") and not view.runner.running)[1], 6000)
    assert ok, f"raytrace pipeline did not finish: {view.message} {view.runner.error}"
    out["levels_seen"] = [lv for lv in levels if lv is not None]
    published = [t["level"] for t in view.runner.trail if t["level"] is not None]
    out["levels_published"] = [lv for i, lv in enumerate(published)
                               if i == 0 or lv != published[i - 1]]
    out["frames_while_refining"] = state.frame - frame0
    out["size"] = list(view.job_size)
    np.save(Path(OUT_DIR) / "viewport.npy", view.linear)
    out["pipeline"] = state.view.pipeline


def scenario_follow_edits(ctx, state, out: dict) -> None:
    from shadelab.lab.pipeline_jobs import pipeline_raytrace
    from shadelab.ui import pipelines

    state.view.render_scale = 0.3
    ctx.yield_(3)
    pipelines.set_pipeline(state, "raytrace")
    view = pipelines.view_of(state)
    assert _wait_job_done(ctx, view), view.message
    before = view.linear.copy()
    out["jobs_before"] = len(view.log)
    ctx.window_focus("//Materials")
    ctx.set_ref("//Materials")
    ctx.item_input_value("material_white/white/kd", 0.5)
    frame0 = state.frame
    _wait(ctx, lambda: len(view.log) > out["jobs_before"], 3000)
    out["frames_to_restart"] = state.frame - frame0
    assert _wait_job_done(ctx, view), view.message
    out["kd"] = state.scene.materials["white"].kd
    out["jobs_after"] = len(view.log)
    fresh = None
    for step in pipeline_raytrace(view.job_scene, view.job_size):
        fresh = step.image if step.image is not None else fresh
    out["max_diff_vs_fresh"] = float(np.abs(view.linear - fresh).max())
    out["max_diff_vs_before"] = float(np.abs(view.linear - before).max())


def scenario_radiosity_resolve(ctx, state, out: dict) -> None:
    from shadelab.lab import pipeline_jobs
    from shadelab.radiosity.patches import uniform_patches
    from shadelab.ui import pipelines

    ctx.yield_(3)
    _open_algorithms(ctx)
    ctx.item_input_value("patches", 120)
    ctx.yield_(3)
    out["patches_setting"] = state.scene.radiosity.patches
    pipelines.set_pipeline(state, "radiosity")
    view = pipelines.view_of(state)
    assert _wait_job_done(ctx, view), view.message
    first = {k: view.stats.get(k) for k in ("form_factors_reused", "ff_token", "patches")}
    energy_before = float(view.soup[:, 3:].sum())
    ctx.window_focus("//Materials")
    ctx.set_ref("//Materials")
    ctx.item_input_value("material_white/white/kd", 0.5)
    _wait(ctx, lambda: view.stats.get("ff_token") and not view.stats.get("done"), 600)
    assert _wait_job_done(ctx, view), view.message
    second = {k: view.stats.get(k) for k in ("form_factors_reused", "ff_token", "patches")}
    out["first"], out["second"] = first, second
    out["soup_shape"] = list(view.soup.shape)
    out["dimmer"] = float(view.soup[:, 3:].sum()) < energy_before
    pipeline_jobs._RADIOSITY_CACHE.clear()      # a fresh solve of the edited scene, here
    fresh = None
    for step in pipeline_jobs.pipeline_radiosity(view.job_scene, None):
        fresh = step.stats.get("soup", fresh)
    scale = float(np.abs(fresh[:, 3:]).max())
    out["max_rel_diff_vs_fresh"] = float(np.abs(view.soup - fresh).max()) / scale
    _ = uniform_patches


def scenario_bad_input(ctx, state, out: dict) -> None:
    from shadelab.ui import render_panel

    ctx.yield_(3)
    _open_algorithms(ctx)
    out["patches_before"] = state.scene.radiosity.patches
    out["path_spp_before"] = state.offline.spp
    ctx.item_input_value("spp (anti-aliasing)", -4)
    ctx.yield_(2)
    ctx.item_input_value("patches", 0)
    ctx.yield_(2)
    ctx.item_input_value("path spp", -4)
    ctx.yield_(3)
    out["spp"] = state.scene.raytrace.spp
    out["patches"] = state.scene.radiosity.patches
    out["path_spp"] = state.offline.spp
    messages = render_panel._refused
    out["spp_message"] = messages.get("RaytraceSettings.spp", "")
    out["patches_message"] = messages.get("RadiositySettings.patches", "")
    out["path_spp_message"] = messages.get("path_spp", "")
    _wait(ctx, lambda: not state.edit_pending, 50)
    out["dirty_after_refusals"] = state.dirty
    ctx.item_input_value("depth", 3)
    ctx.yield_(3)
    out["depth"] = state.scene.raytrace.depth
    from imgui_bundle import imgui
    from imgui_bundle.immapp import testing

    testing.capture(ctx, str(Path(OUT_DIR) / "bad_input.png"),
                    flags=imgui.test_engine.CaptureFlags_.hide_mouse_cursor)


def scenario_raster_pipelines(ctx, state, out: dict) -> None:
    ctx.yield_(3)
    _choose_pipeline(ctx, "z-buffer + Gouraud")
    ctx.yield_(3)
    out["gouraud"] = [state.scene.render.shading, state.scene.render.visibility]
    _choose_pipeline(ctx, "list priority + Phong")
    ctx.yield_(3)
    out["painter"] = [state.scene.render.shading, state.scene.render.visibility]
    ctx.window_focus("//Materials")
    ctx.yield_(2)
    ctx.set_ref("//Materials")
    ctx.item_open("material_white/white/transparency, reflection, emission")
    ctx.yield_(2)
    base = "material_white/white/transparency, reflection, emission"
    out["kr_follows"] = state.scene.materials["white"].kr
    ctx.item_uncheck(f"{base}/kr = ks")
    ctx.yield_(2)
    out["kr_set"] = state.scene.materials["white"].kr
    ctx.set_ref(f"//Materials/{base}")
    ctx.combo_click("transparency/filtered I1 + kt Ot I2")
    ctx.yield_(2)
    out["transparency"] = state.scene.materials["white"].transparency


OUT_DIR = "."


def _main(name: str, out_dir: str) -> int:
    global OUT_DIR
    OUT_DIR = out_dir
    return run_scenario_main(globals(), name, out_dir, "cornell", WINDOW)


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1], sys.argv[2]))
