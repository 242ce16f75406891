"""The viewer's logic without a window: probe vs GPU, jobs, undo, autosave, camera, CLI errors."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

from shadelab.cli import main
from shadelab.lab.camera_control import orbit, pan, zoom
from shadelab.lab.jobs import JobRunner, difference, iter_reference_raster
from shadelab.lab.probe import probe
from shadelab.lab.state import AppState, History, autosave_path, load_session, save_session
from shadelab.progress import Progress
from shadelab.scene import load_preset
from shadelab.scene.preset import scene_to_dict

# ---------------------------------------------------------------- command line


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def test_no_display_says_use_render_or_xvfb(monkeypatch, capsys):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main([]) == 2
    line = _one_error_line(capsys)
    assert "shadelab render" in line and "Xvfb" in line


@pytest.mark.parametrize("argv, expected", [
    (["view", "no-such-preset"], "unknown preset 'no-such-preset'"),
    (["view", "cornell", "--probe", "1;2"], "--probe '1;2'"),
    (["view", "cornell", "--window", "big"], "--size 'big'"),
    (["view", "cornell", "--set", "materials.white.kd=7"], "materials.white.kd"),
])
def test_view_bad_input_is_one_line_exit_2(monkeypatch, capsys, argv, expected):
    monkeypatch.setenv("DISPLAY", ":12345")  # never reached: the input fails first
    assert main(argv) == 2
    assert expected in _one_error_line(capsys)


# ---------------------------------------------------------------- probe (numpy) vs GPU


@pytest.mark.gl
@pytest.mark.parametrize("preset", ["cornell", "sphere-shading"])
@pytest.mark.parametrize("shading", ["flat", "gouraud", "phong"])
@pytest.mark.parametrize("specular", ["phong", "blinn"])
def test_probe_terms_match_the_gpu_pixel(gl_ctx, preset, shading, specular):
    """The probe's reference sum equals what the GPU drew (rtol 1e-4, atol 1e-5)."""
    from shadelab.ui.viewport import Viewport

    scene = load_preset(preset)
    for m in scene.materials.values():  # give every surface a highlight to check
        m.ks, m.n = max(m.ks, 0.3), 20.0
    size = (48, 40)
    vp = Viewport(gl_ctx)
    try:
        vp.draw_scene("main", scene, size, shading, specular)
        image = vp.read_linear("main")
        checked = 0
        for y in range(2, size[1], 7):
            for x in range(3, size[0], 9):
                result = probe(scene, size, (x, y), shading, specular)
                if result is None:
                    continue
                gpu = vp.read_pixel("main", (x, y))
                np.testing.assert_allclose(gpu, image[y, x], rtol=0, atol=0)
                np.testing.assert_allclose(gpu, result.reference, rtol=1e-4, atol=1e-5)
                if shading == "phong":  # the listed terms add up to the pixel
                    np.testing.assert_allclose(result.terms.total, result.reference, rtol=1e-12)
                checked += 1
        assert checked >= 12
    finally:
        vp.release()


@pytest.mark.gl
def test_display_pass_is_exposure_then_srgb_and_heat_map_of_equal_images_is_black(gl_ctx):
    from shadelab.shading.conventions import to_srgb8
    from shadelab.ui.viewport import Viewport

    scene = load_preset("cornell")
    vp = Viewport(gl_ctx)
    try:
        pane = vp.draw_scene("a", scene, (40, 32), "phong", "phong")
        vp.present(pane, 2.0)
        shown = vp.read_display("a").astype(int)
        expected = to_srgb8(vp.read_linear("a"), 2.0).astype(int)
        assert np.abs(shown - expected).max() <= 1
        twin = vp.draw_scene("b", scene, (40, 32), "phong", "phong")
        diff = vp.pane("diff", (40, 32))
        vp.present(diff, 1.0, pane, twin, 0.05)
        assert vp.read_display("diff").max() == 0
        flat = vp.draw_scene("c", scene, (40, 32), "flat", "phong")
        vp.present(diff, 1.0, pane, flat, 0.05)
        assert vp.read_display("diff").max() > 100  # flat vs Phong differ somewhere
    finally:
        vp.release()


@pytest.mark.gl
def test_reference_raster_job_matches_the_gpu_image(gl_ctx):
    from shadelab.raster.offscreen import render_image

    scene = load_preset("cornell")
    steps = list(iter_reference_raster(scene, (40, 30), rows_per_chunk=8))
    assert [round(s.fraction, 3) for s in steps[:4]] == [0.267, 0.533, 0.8, 1.0]
    gpu = render_image(scene, (40, 30), "phong", "phong")
    err = difference(steps[-1].image, gpu)
    assert err["max_abs"] < 1e-3 * float(gpu.max()), err


# ---------------------------------------------------------------- probe math without GL


def test_probe_of_the_floor_lists_the_lecture_terms():
    """Cornell floor straight below the light: N = +y, f_att = 1/d^2, diffuse = Ip kd Od N.L/d^2."""
    scene = load_preset("cornell")
    size = (64, 64)
    result = probe(scene, size, (32, 60), "phong", "phong")
    assert result is not None and result.hit.mesh.material == "white"
    np.testing.assert_allclose(result.normal, [0, 1, 0], atol=1e-12)
    light = scene.lights[0]
    d = np.linalg.norm(np.subtract(light.position, result.point))
    term = result.terms.lights[0]
    assert term.f_att == pytest.approx(1.0 / d**2, rel=1e-12)
    n_dot_l = (light.position[1] - result.point[1]) / d
    expected = np.asarray(light.Ip) * np.asarray(scene.materials["white"].Od) * n_dot_l / d**2
    np.testing.assert_allclose(term.diffuse, expected, rtol=1e-12)
    assert not bool(term.clamp_active)
    assert probe(scene, size, (0, 0)) is None  # past the open front: background, no terms


def test_probe_shows_the_attenuation_clamp():
    scene = load_preset("cornell")
    light = scene.lights[0]
    light.attenuation, light.c1, light.c2, light.c3 = "lecture", 0.5, 0.0, 0.0
    result = probe(scene, (32, 32), (16, 30))
    assert bool(result.terms.lights[0].clamp_active) and result.terms.lights[0].f_att == 1.0


# ---------------------------------------------------------------- camera


def test_orbit_keeps_the_distance_zoom_scales_it_pan_moves_both():
    scene = load_preset("cornell")
    cam = scene.camera
    dist = np.linalg.norm(np.subtract(cam.eye, cam.target))
    orbit(cam, 40.0, -25.0)
    assert np.linalg.norm(np.subtract(cam.eye, cam.target)) == pytest.approx(dist, rel=1e-12)
    assert not np.allclose(cam.eye, (278.0, 273.0, -800.0))
    zoom(cam, 2.0)
    assert np.linalg.norm(np.subtract(cam.eye, cam.target)) == pytest.approx(dist * 0.81)
    before = np.subtract(cam.eye, cam.target)
    target = np.asarray(cam.target)
    pan(cam, 10.0, 5.0, 500)
    np.testing.assert_allclose(np.subtract(cam.eye, cam.target), before, atol=1e-9)
    assert np.linalg.norm(np.asarray(cam.target) - target) > 0.0


# ---------------------------------------------------------------- undo, files, autosave


def test_history_undo_redo_and_a_new_edit_drops_the_redo_branch():
    scene = load_preset("cornell")
    history = History(scene)
    scene.materials["white"].kd = 0.5
    history.push(scene)
    history.push(scene)  # unchanged: no new snapshot
    scene.materials["white"].kd = 0.25
    history.push(scene)
    assert len(history.snapshots) == 3
    assert history.undo().materials["white"].kd == 0.5
    assert history.undo().materials["white"].kd == 1.0
    assert history.undo() is None
    assert history.redo().materials["white"].kd == 0.5
    edited = history.redo()
    edited.materials["red"].kd = 0.1
    history.index = 1
    history.push(edited)
    assert not history.can_redo() and len(history.snapshots) == 3


def test_open_broken_preset_keeps_the_scene_and_shows_the_error(tmp_path):
    state = AppState.from_scene(load_preset("cornell"), "cornell")
    state.scene.materials["white"].kd = 0.3
    bad = tmp_path / "bad.toml"
    bad.write_text("[materials.white]\nkd = 'much'\n")
    assert not state.open_preset(str(bad))
    assert "bad.toml" in state.error and state.scene.materials["white"].kd == 0.3
    mesh = tmp_path / "mesh.toml"
    mesh.write_text('schema_version = 1\n[[objects]]\nshape = "mesh"\npath = "missing.obj"\n'
                    'material = "m"\n[materials.m]\n')
    assert not state.open_preset(str(mesh))
    assert "missing.obj" in state.error and state.scene.name == "cornell"


def test_save_as_round_trips_and_clears_the_unsaved_flag(tmp_path):
    state = AppState.from_scene(load_preset("cornell"), "cornell")
    state.scene.materials["white"].kd = 0.4
    state.commit_edit()
    assert state.dirty and state.title().endswith("*")
    assert state.save_as(str(tmp_path / "mine"))
    assert not state.dirty and not state.title().endswith("*")
    again = load_preset(str(tmp_path / "mine.toml"))
    assert scene_to_dict(again) == scene_to_dict(state.scene)
    assert not state.save_as(str(tmp_path / "no" / "such" / "dir.toml"))
    assert "cannot write" in state.error


def test_autosave_honours_xdg_state_home_and_restores(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "xdg"))
    assert autosave_path() == tmp_path / "xdg" / "shadelab" / "autosave.toml"
    assert not load_session() and load_session().scene is None
    scene = load_preset("cornell")
    scene.lights[0].Ip = (1.0, 2.0, 3.0)
    save_session(scene, "cornell")
    restored, source = load_session().scene, load_session().source
    assert source == "cornell" and restored.name == "cornell"
    assert restored.base_dir == scene.base_dir
    assert scene_to_dict(restored) == scene_to_dict(scene)


# ---------------------------------------------------------------- the job runner


def _slow_job(closed: threading.Event, steps: int = 200, pause: float = 0.01):
    try:
        for i in range(steps):
            time.sleep(pause)
            yield Progress(np.full((2, 2, 3), i, np.float32), (i + 1) / steps, f"step {i}")
    finally:
        closed.set()


def test_job_runs_off_thread_and_cancel_closes_the_generator():
    closed = threading.Event()
    runner = JobRunner()
    runner.start("slow", lambda: _slow_job(closed))
    deadline = time.perf_counter() + 2.0
    while runner.snapshot()[0] is None and time.perf_counter() < deadline:
        time.sleep(0.005)
    assert runner.running
    runner.cancel(wait=True)
    assert closed.is_set() and runner.cancelled and not runner.running
    assert runner.snapshot()[0].fraction < 1.0
    assert runner.elapsed < 1.5


def test_job_runs_to_the_end_and_reports_errors():
    closed = threading.Event()
    runner = JobRunner()
    runner.start("short", lambda: _slow_job(closed, steps=5, pause=0.0))
    runner._thread.join(2.0)
    assert runner.snapshot()[0].fraction == 1.0 and not runner.cancelled and not runner.error

    def broken():
        yield Progress(None, 0.1)
        raise ValueError("bad patch count")

    runner.start("broken", broken)
    runner._thread.join(2.0)
    assert runner.error == "ValueError: bad patch count" and not runner.running


def test_available_jobs_lists_every_renderer_with_a_reason_when_missing():
    from shadelab.lab.jobs import available_jobs

    kinds = available_jobs()
    labels = [k.label for k in kinds]
    assert labels[0].startswith("Reference raster") and kinds[0].make is not None
    assert any(label.startswith("Whitted") for label in labels)
    for kind in kinds:
        assert (kind.make is None) == bool(kind.reason)


def test_legend_is_written_in_a_margin_under_the_image():
    from shadelab.lab.legend import burn_legend, legend_lines

    state = AppState.from_scene(load_preset("cornell"), "cornell")
    image = np.full((200, 300, 3), 128, np.uint8)
    out = burn_legend(image, state)
    assert out.shape[1:] == image.shape[1:] and out.shape[0] > image.shape[0] + 20
    assert np.array_equal(out[:200], image)          # the picture is whole: nothing covered
    margin = out[200:].astype(int)
    assert (margin > 200).any() and (margin < 60).any()  # white text on the dark margin
    assert "Phong shading" in legend_lines(state)[0].replace("phong shading", "Phong shading")


def test_overlays_ray_tree_and_radiosity_soup_shapes_and_colors():
    from types import SimpleNamespace

    from shadelab.lab import overlays

    node = SimpleNamespace
    leaf = node(kind="shadow", origin=np.zeros(3), direction=np.array([0.0, 1.0, 0.0]),
                end=None, shadow=0.0)
    root = node(kind="primary", origin=np.ones(3), direction=np.array([1.0, 0.0, 0.0]),
                end=np.array([4.0, 1.0, 1.0]), shadow=1.0)
    root.flatten = lambda: iter([(0, root), (1, leaf)])
    lines = overlays.ray_tree_lines(root, miss_length=10.0)
    assert lines.shape == (4, 6)
    np.testing.assert_allclose(lines[1, :3], [4.0, 1.0, 1.0])       # primary ends at its hit
    np.testing.assert_allclose(lines[3, :3], [0.0, 10.0, 0.0])      # a miss runs on
    np.testing.assert_allclose(lines[2, 3:], overlays.RAY_COLORS["blocked"])
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    soup = overlays.radiosity_soup([(v, np.array([[0, 1, 2]]), v * 2.0)])
    assert soup.shape == (3, 6) and soup.dtype == np.float32
    np.testing.assert_allclose(soup[:, 3:], 2.0 * v)


def test_wireframe_and_normal_glyphs_follow_the_mesh():
    from shadelab.geometry.mesh import scene_meshes
    from shadelab.lab import overlays

    meshes = scene_meshes(load_preset("cornell"))
    faces = sum(len(m.faces) for m in meshes)
    assert overlays.wireframe(meshes).shape == (6 * faces, 6)
    flat = overlays.normal_glyphs(meshes, 10.0, "flat")
    assert flat.shape == (2 * faces, 6)
    lengths = np.linalg.norm(flat[1::2, :3] - flat[0::2, :3], axis=1)
    np.testing.assert_allclose(lengths, 10.0, rtol=1e-5)
    # one glyph per vertex (per side of a crease), not one per corner of every face
    pairs = sum(len(np.unique(np.c_[m.faces.reshape(-1), np.round(
        m.corner_normals.reshape(-1, 3) * 1e6)], axis=0)) for m in meshes)
    assert pairs < 3 * faces
    assert overlays.normal_glyphs(meshes, 10.0, "phong").shape == (2 * pairs, 6)


def test_view_restores_the_autosaved_session_unless_fresh_or_another_preset(tmp_path,
                                                                          monkeypatch, capsys):
    import argparse

    from shadelab.cli.view import load_scene

    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "xdg"))
    scene = load_preset("cornell")
    scene.materials["red"].kd = 0.125
    save_session(scene, "cornell")

    def args(preset=None, fresh=False, overrides=()):
        return argparse.Namespace(preset=preset, fresh=fresh, set=list(overrides))

    restored, source, was_restored = load_scene(args())
    assert source == "cornell" and restored.materials["red"].kd == 0.125 and was_restored
    assert "restored the autosaved session" in capsys.readouterr().out
    assert load_scene(args("cornell"))[0].materials["red"].kd == 0.125
    assert load_scene(args("cornell", fresh=True))[0].materials["red"].kd == 1.0
    other, name, was_restored = load_scene(args("sphere-shading"))
    assert not was_restored
    assert name == "sphere-shading" and "red" not in other.materials
    overridden = load_scene(args("cornell", overrides=["materials.red.kd=0.5"]))[0]
    assert overridden.materials["red"].kd == 0.5


def test_a_picklable_job_runs_in_the_worker_process_and_cancels():
    from shadelab.lab.jobs import iter_reference_raster

    scene = load_preset("cornell")
    runner = JobRunner()
    try:
        runner.start("ref", lambda: iter_reference_raster(scene, (32, 24)),
                     call=(iter_reference_raster, scene, (32, 24)))
        assert runner.in_process
        runner._thread.join(60.0)
        last = runner.snapshot()[0]
        assert not runner.error and last.fraction == 1.0 and last.image.shape == (24, 32, 3)
        local = list(iter_reference_raster(scene, (32, 24)))[-1].image
        np.testing.assert_array_equal(last.image, local)  # the same numbers came across
        big = (640, 480)  # 60 chunks of rows: the cancel lands long before the end
        runner.start("big", lambda: None, call=(iter_reference_raster, scene, big))
        deadline = time.perf_counter() + 30.0
        while runner.snapshot()[0] is None and time.perf_counter() < deadline:
            time.sleep(0.01)
        runner.cancel(wait=True)
        assert runner.cancelled and not runner.running
        assert runner.snapshot()[0].fraction < 1.0
    finally:
        runner.shutdown()
    assert runner.worker.process is None


def test_open_a_mesh_file_adds_it_and_a_broken_one_keeps_the_scene(tmp_path):
    state = AppState.from_scene(load_preset("cornell"), "cornell")
    count = len(state.scene.objects)
    good = tmp_path / "tetra.obj"
    good.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                    "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    assert state.open_file(str(good)) and len(state.scene.objects) == count + 1
    added = state.scene.objects[-1]
    assert added.shape == "mesh" and added.material in state.scene.materials
    from shadelab.geometry.mesh import scene_bounds, scene_meshes

    lo, hi = scene_bounds([scene_meshes(state.scene)[-1]])
    assert np.max(hi - lo) == pytest.approx(0.3 * 800.0, rel=1e-6)  # fitted to the view
    assert state.history.can_undo()
    broken = tmp_path / "broken.obj"
    broken.write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")  # one zero-area triangle
    assert not state.open_file(str(broken))
    assert "broken.obj" in state.error and len(state.scene.objects) == count + 1
    assert not state.open_file(str(tmp_path / "missing.ply"))
    assert "not found" in state.error


def test_save_never_overwrites_a_shipped_preset(tmp_path, monkeypatch):
    """Save (and Ctrl+S) on a preset ShadeLab ships asks where (Save as) and leaves the file;
    on the user's own file it writes in place."""
    from shadelab.resources import presets_dir
    from shadelab.ui import dialogs, scene_panel

    asked = []
    monkeypatch.setattr(dialogs, "ask", lambda state, purpose: asked.append(purpose))
    shipped = presets_dir() / "cornell.toml"
    before = shipped.read_bytes()
    state = AppState.from_scene(load_preset("cornell"), "cornell")
    state.preset_path = str(shipped)
    state.scene.materials["white"].kd = 0.5
    try:
        scene_panel.save_here(state)
        assert asked == ["save"] and shipped.read_bytes() == before
    finally:  # a regression must not leave the shipped preset changed
        if shipped.read_bytes() != before:
            shipped.write_bytes(before)
    own = tmp_path / "mine.toml"
    state.preset_path = str(own)
    scene_panel.save_here(state)
    assert asked == ["save"] and load_preset(str(own)).materials["white"].kd == 0.5


def slow_stages(scene, size):
    """A picklable job: a step, then a stage longer than the runner's KILL_AFTER, then more."""
    from shadelab.lab.jobs import KILL_AFTER
    from shadelab.progress import Progress

    yield Progress(None, 0.1, "stage 1")
    time.sleep(KILL_AFTER + 1.0)
    yield Progress(None, 0.5, "stage 2")
    yield Progress(None, 1.0, "stage 3")


@pytest.mark.parametrize("kill_after", [None, 0.5])
def test_a_soft_cancel_waits_for_the_step_a_hard_one_ends_the_worker(kill_after):
    """A kernel warm-up is cancelled softly (kill_after=None): it stops after the stage it is
    in, and the worker process (with the kernels it loaded) lives on."""
    runner = JobRunner()
    try:
        runner.start("slow", lambda: None, call=(slow_stages, None, (1, 1)))
        deadline = time.perf_counter() + 60.0
        while runner.snapshot()[0] is None and time.perf_counter() < deadline:
            time.sleep(0.01)
        pid = runner.worker.process.pid
        runner.cancel(kill_after=kill_after)
        runner._thread.join(30.0)
        assert runner.cancelled and not runner.running
        if kill_after is None:   # stopped after stage 2, by itself: same live worker
            assert runner.snapshot()[0].message == "stage 2" and not runner.error
            assert runner.worker.process.is_alive() and runner.worker.process.pid == pid
        else:                    # ended mid-stage: the worker was killed
            assert runner.snapshot()[0].message == "stage 1"
            assert runner.worker.process is None   # ended (a new one starts on demand)
    finally:
        runner.shutdown()
