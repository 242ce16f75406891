"""The offline-render side panel: start/cancel a job, watch it, compare it with the raster view."""

from __future__ import annotations

import numpy as np
from imgui_bundle import imgui

from app.scene.preset import clone_scene
from app.shading.conventions import to_srgb8
from app.ui import panels
from app.ui.jobs import available_jobs, difference
from app.ui.state import AppState

SIZES = (32, 64, 96, 128, 192, 256, 384, 512)


def heat_map(a: np.ndarray, b: np.ndarray, scale: float) -> np.ndarray:
    """(H, W, 3) uint8: max-channel |a - b| / scale through black-blue-green-yellow-red."""
    t = np.clip(np.abs(a - b).max(axis=-1) / max(scale, 1e-12), 0.0, 1.0) * 4.0
    stops = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0], [1, 1, 0], [1, 0, 0]], np.float64)
    i = np.minimum(t.astype(int), 3)
    f = (t - i)[..., None]
    return np.round((stops[i] * (1 - f) + stops[i + 1] * f) * 255).astype(np.uint8)


def kinds(state: AppState):
    if state.job_kinds is None:
        state.job_kinds = available_jobs()
    return state.job_kinds


def start_job(state: AppState, index: int) -> None:
    """Render the raster view to compare with (GL thread), then start the job's worker."""
    kind = kinds(state)[index]
    if kind.make is None:
        state.error = f"{kind.label}: not available ({kind.reason})"
        return
    scene = clone_scene(state.scene)
    size = _job_size(state)
    if state.gl is not None:
        state.gl.draw_scene("job_raster", scene, size, kind.raster_shading, scene.render.specular)
        state.job_raster = state.gl.read_linear("job_raster")
        state.gl.restore()
    state.job_kind, state.job_version, state.job_compare = index, -1, None
    state.job.start(kind.label, lambda: kind.make(scene, size))


def start_job_by_label(state: AppState, label: str) -> None:
    for i, kind in enumerate(kinds(state)):
        if kind.label.lower().startswith(label.lower()):
            start_job(state, i)
            return
    state.error = f"--job '{label}': expected one of " + ", ".join(k.label for k in kinds(state))


def _job_size(state: AppState) -> tuple[int, int]:
    """The job's image: state.job_size pixels high, at the viewport's aspect ratio."""
    w, h = state.viewport_size if state.viewport_size[1] > 0 else (1, 1)
    height = state.job_size
    return max(int(round(height * w / max(h, 1))), 1), height


def _upload_results(state: AppState) -> None:
    """Re-upload the job's image, its raster partner and their difference when new."""
    latest, version = state.job.snapshot()
    if latest is None or latest.image is None or version == state.job_version:
        return
    state.job_version = version
    exposure = state.scene.render.exposure
    image = np.asarray(latest.image, dtype=np.float32)
    vp = state.gl
    vp.upload_image("job_result", to_srgb8(image, exposure))
    raster = state.job_raster
    if raster is not None and raster.shape == image.shape:
        vp.upload_image("job_raster", to_srgb8(raster, exposure))
        scale = max(float(np.abs(raster).max()) * exposure, 1e-6) * 0.1
        vp.upload_image("job_diff", heat_map(image * exposure, raster * exposure, scale))
        state.job_compare = difference(image, raster) | {"heat_full_scale": scale / exposure}


def _show(state: AppState, key: str, caption: str, width: float) -> None:
    tex = state.gl.images.get(key)
    if tex is None:
        return
    w, h = tex.size
    imgui.begin_group()
    imgui.image(imgui.ImTextureRef(tex.glo), imgui.ImVec2(width, width * h / w))
    imgui.text(caption)
    imgui.end_group()


def draw_offline_panel(state: AppState) -> bool:
    """Pick a renderer, run it off the UI thread, compare its image with the raster view."""
    job, options = state.job, kinds(state)
    labels = [k.label + ("" if k.make else " (not available)") for k in options]
    _, state.job_kind = imgui.combo("Renderer", state.job_kind, labels)
    kind = options[state.job_kind]
    if kind.make is None:
        imgui.text_colored(panels.DIM_COLOR, f"not available: {kind.reason}")
    index = SIZES.index(state.job_size) if state.job_size in SIZES else 3
    _, index = imgui.combo("Height (px)", index, [str(s) for s in SIZES])
    state.job_size = SIZES[index]
    imgui.begin_disabled(job.running or kind.make is None)
    if imgui.button("Start"):
        start_job(state, state.job_kind)
    imgui.end_disabled()
    imgui.same_line()
    imgui.begin_disabled(not job.running)
    if imgui.button("Cancel"):
        job.cancel()
    imgui.end_disabled()
    latest, _ = job.snapshot()
    if job.started:
        fraction = latest.fraction if latest else 0.0
        word = "running" if job.running else ("cancelled" if job.cancelled else "done")
        if job.error:
            word = "failed"
        imgui.progress_bar(fraction, imgui.ImVec2(-1, 0),
                           f"{job.name}: {word} {fraction * 100:.0f}%")
        imgui.text(f"elapsed {job.elapsed:.1f} s   {latest.message if latest else ''}")
    if job.error:
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(panels.ERROR_COLOR, job.error)
        imgui.pop_text_wrap_pos()
    if state.gl is None:
        return False
    _upload_results(state)
    width = (imgui.get_content_region_avail().x - 16) / 3
    if "job_result" in state.gl.images and width > 8:
        _show(state, "job_result", "offline", width)
        imgui.same_line()
        _show(state, "job_raster", f"raster ({kind.raster_shading})", width)
        imgui.same_line()
        _show(state, "job_diff", "|difference|", width)
    if state.job_compare:
        c = state.job_compare
        imgui.text(f"RMSE {c['rmse']:.4g}  max |diff| {c['max_abs']:.4g}  "
                   f"relative RMSE {c['relative_rmse']:.3%}")
        imgui.text_colored(panels.DIM_COLOR, f"heat map: red = {c['heat_full_scale']:.3g}")
    if latest is not None and latest.stats and not job.running:
        imgui.text_wrapped("  ".join(f"{k}: {v}" for k, v in latest.stats.items()))
    return False
