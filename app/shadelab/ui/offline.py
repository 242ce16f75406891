"""The offline-render side panel: start/cancel a job, watch it, compare it with the raster view."""

from __future__ import annotations

import threading

import numpy as np
from imgui_bundle import imgui

from shadelab.lab.jobs import available_jobs, difference
from shadelab.lab.state import AppState
from shadelab.pipelines import viewport_names
from shadelab.scene.preset import clone_scene
from shadelab.shading.conventions import heat_map, to_srgb8
from shadelab.ui import panels
from shadelab.ui.pipelines import object_label

SIZES = (32, 64, 96, 128, 192, 256, 384, 512, 768, 1024)
SAMPLES = (1, 4, 16, 64, 256)


def kinds(state: AppState):
    if state.offline.kinds is None:
        state.offline.kinds = available_jobs()
    return state.offline.kinds


_finder: dict = {}  # the thread looking for the renderers, and what it found


def kinds_when_found(state: AppState):
    """The job kinds, or None while a thread still looks for them: finding them imports
    every renderer (numba, embree; a second or more), which the first frame must not wait
    for."""
    if state.offline.kinds is not None:
        return state.offline.kinds
    thread = _finder.get("thread")
    if thread is None:
        def find() -> None:
            try:
                _finder["kinds"] = available_jobs()
            except Exception as exc:  # reported by the synchronous call below
                _finder["error"] = exc
        thread = _finder["thread"] = threading.Thread(target=find, name="find-renderers",
                                                      daemon=True)
        thread.start()
    if thread.is_alive():
        return None
    state.offline.kinds = _finder.get("kinds") or available_jobs()
    return state.offline.kinds


def start_job(state: AppState, index: int) -> None:
    """Render the raster view to compare with (GL thread), then start the job's worker."""
    kind = kinds(state)[index]
    if kind.make is None:
        state.error = f"{kind.label}: not available ({kind.reason})"
        return
    scene = clone_scene(state.scene)
    if kind.samples:
        scene.raytrace.spp = state.offline.spp
    size = _job_size(state)
    # the raster view to compare with: drawn by the GL side before the panels' next frame
    state.gpu.request("job_raster", "raster", scene=scene, size=size,
                      shading=kind.raster_shading, specular=scene.render.specular)
    state.offline.raster = None
    state.offline.kind, state.offline.version, state.offline.comparison = index, -1, None
    state.offline.scene, state.offline.size_px = scene, size
    state.offline.ray_tree = state.offline.ray_tree_pixel = None
    state.offline.overlay_version += 1
    state.offline.runner.start(kind.label, lambda: kind.make(scene, size),
                               call=(kind.make, scene, size))


def start_job_by_label(state: AppState, label: str) -> None:
    """--job and the Studies panel: a pipeline's name, else a prefix of its label."""
    options = kinds(state)
    for i, kind in enumerate(options):
        if kind.pipeline and kind.pipeline == label:
            start_job(state, i)
            return
    for i, kind in enumerate(options):
        if label.strip() and kind.label.lower().startswith(label.lower()):
            start_job(state, i)
            return
    state.error = f"--job '{label}': expected one of " + ", ".join(k.label for k in kinds(state))


def _job_size(state: AppState) -> tuple[int, int]:
    """The job's image: state.offline.size pixels high, at the viewport's aspect ratio."""
    w, h = state.view.viewport_size if state.view.viewport_size[1] > 0 else (1, 1)
    height = state.offline.size
    return max(int(round(height * w / max(h, 1))), 1), height


def update(state: AppState) -> None:
    """Once a frame, whichever panel is visible: collect the job's latest image (a job started
    with the Offline panel hidden, by --job or the Studies panel, still ends)."""
    if not state.gpu.attached:
        return
    _upload_results(state)
    if "job_raster" in state.gpu.errors:
        state.error = f"raster view to compare with: {state.gpu.errors.pop('job_raster')}"


def _upload_results(state: AppState) -> None:
    """Re-upload the job's image, its raster partner and their difference when new."""
    raster = state.gpu.take("job_raster")
    if raster is not None:     # (the job's image, if already here, is compared again)
        state.offline.raster, state.offline.version = raster, -1
    latest, version = state.offline.runner.snapshot()
    if latest is None or version == state.offline.version:
        return
    state.offline.version = version
    _take_solution(state, latest)
    if latest.image is None:
        return
    exposure = state.scene.render.exposure
    image = np.asarray(latest.image, dtype=np.float32)
    gpu = state.gpu
    gpu.upload("job_result", to_srgb8(image, exposure))
    raster = state.offline.raster
    if raster is not None and raster.shape == image.shape:
        gpu.upload("job_raster", to_srgb8(raster, exposure))
        scale = max(float(np.abs(raster).max()) * exposure, 1e-6) * 0.1
        gpu.upload("job_diff", heat_map(image * exposure, raster * exposure, scale))
        state.offline.comparison = difference(image, raster) | {"heat_full_scale": scale / exposure}
        if not state.offline.runner.running:  # FLIP (~0.1 s at 128^2): once, on the final image
            from shadelab.studies.metrics import flip

            state.offline.comparison["flip"] = flip(image, raster, exposure=exposure)


def _take_solution(state: AppState, latest) -> None:
    """Keep a radiosity solution's display triangles (drawn in the viewport on request)."""
    solution = latest.stats.get("solution") if latest.stats else None
    if solution is not None and hasattr(solution, "display_meshes"):
        from shadelab.lab.overlays import radiosity_soup

        state.offline.radiosity_soup = radiosity_soup(solution.display_meshes())
        state.offline.overlay_version += 1


def _show(state: AppState, key: str, caption: str, width: float) -> tuple[int, int] | None:
    """Show an uploaded image; returns the image pixel clicked, if any."""
    tex = state.gpu.texture(key)
    if tex is None:
        return None
    w, h = tex.size
    imgui.begin_group()
    origin = imgui.get_cursor_screen_pos()
    imgui.image(imgui.ImTextureRef(tex.id), imgui.ImVec2(width, width * h / w))
    clicked = None
    if imgui.is_item_clicked():
        mouse = imgui.get_io().mouse_pos
        x, y = int((mouse.x - origin.x) * w / width), int((mouse.y - origin.y) * w / width)
        if 0 <= x < w and 0 <= y < h:
            clicked = (x, y)
    imgui.text_wrapped(caption)
    imgui.end_group()
    return clicked


def trace_tree(state: AppState, pixel: tuple[int, int]) -> None:
    """The ray tree of a pixel of the ray-traced image, drawn in 3D in the viewport."""
    try:
        from shadelab.raytrace.tree import trace_pixel_tree
    except ImportError as exc:
        state.error = f"ray tree not available ({exc})"
        return
    try:
        offline = state.offline
        offline.ray_tree = trace_pixel_tree(offline.scene, offline.size_px, *pixel)
        state.offline.ray_tree_pixel = pixel
        state.offline.overlay_version += 1
    except Exception as exc:  # shown in the app; the session goes on
        state.error = f"ray tree of pixel {pixel}: {exc}"


def draw_ray_tree(state: AppState) -> None:
    root = state.offline.ray_tree
    if root is None:
        return
    imgui.text_wrapped(f"ray tree of pixel {state.offline.ray_tree_pixel} (drawn in the viewport; "
               f"total {_rgb(root.total())})")
    if imgui.small_button("Clear ray tree"):
        state.offline.ray_tree = None
        state.offline.overlay_version += 1
        return
    flags = imgui.TableFlags_.borders | imgui.TableFlags_.row_bg | imgui.TableFlags_.scroll_y
    if imgui.begin_table("raytree", 4, flags, imgui.ImVec2(0, 160)):
        for head in ("ray", "hit", "weight", "contribution"):
            imgui.table_setup_column(head)
        imgui.table_headers_row()
        for depth, node in root.flatten():
            imgui.table_next_row()
            imgui.table_next_column()
            label = node.kind + (f" L{node.light} S={node.shadow:g}" if node.kind == "shadow"
                                 else "")
            imgui.text_wrapped("  " * depth + label)
            imgui.table_next_column()
            imgui.text_wrapped("miss" if node.end is None
                       else object_label(state.offline.scene, node.object))  # name (material)
            imgui.table_next_column()
            imgui.text_wrapped(_rgb(node.weight))
            imgui.table_next_column()
            imgui.text_wrapped(_rgb(node.contribution))
        imgui.end_table()


def _rgb(v) -> str:
    return "(" + ", ".join(f"{float(c):.3g}" for c in np.asarray(v).reshape(-1)[:3]) + ")"


def work_done(latest) -> str:
    """Progress in the job's own units: rays traced, paths sampled, patches and shots."""
    if latest is None:
        return ""
    stats = latest.stats or {}
    if "samples" in stats:
        return f"{int(stats['samples']):,} samples, {int(stats.get('rays', 0)):,} rays"
    if "rays" in stats:
        return f"{int(stats['rays']):,} rays"
    if "paths" in stats:
        return f"{int(stats['paths']):,} paths"
    if "patches" in stats:
        history = stats.get("history") or {}
        shots = len(history.get("iteration", [])) if isinstance(history, dict) else 0
        return f"{stats['patches']} patches, {shots} iterations/shots"
    return latest.message


def idle_note(job) -> str:
    """What the panel says before its first job ("" once one started): no empty result."""
    if job.started:
        return ""
    return "no offline job yet: pick a renderer and a size, then Start"


def draw_offline_panel(state: AppState) -> bool:
    """Pick a renderer, run it off the UI thread, compare its image with the raster view."""
    job, options = state.offline.runner, kinds_when_found(state)
    if options is None:
        imgui.text_colored(panels.DIM_COLOR, "looking for the offline renderers ...")
        return False
    labels = [k.label + ("" if k.make else " (not available)") for k in options]
    _, state.offline.kind = imgui.combo("Renderer", state.offline.kind, labels)
    kind = options[state.offline.kind]
    if kind.make is None:
        imgui.text_colored(panels.DIM_COLOR, f"not available: {kind.reason}")
    index = SIZES.index(state.offline.size) if state.offline.size in SIZES else SIZES.index(256)
    _, index = imgui.combo("Height (px)", index, [str(s) for s in SIZES])
    state.offline.size = SIZES[index]
    if kind.samples:
        index = SAMPLES.index(state.offline.spp) if state.offline.spp in SAMPLES else 0
        _, index = imgui.combo("Samples / pixel", index, [str(n) for n in SAMPLES])
        state.offline.spp = SAMPLES[index]
    imgui.begin_disabled(job.running or kind.make is None)
    if imgui.button("Start"):
        start_job(state, state.offline.kind)
    imgui.end_disabled()
    imgui.same_line()
    imgui.begin_disabled(not job.running)
    if imgui.button("Cancel"):
        job.cancel()
    imgui.end_disabled()
    latest, _ = job.snapshot()
    if idle_note(job):   # wrapped: a projector at 1024x768 leaves the panel narrow
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(panels.DIM_COLOR, idle_note(job))
        imgui.pop_text_wrap_pos()
    if job.started:
        fraction = latest.fraction if latest else 0.0
        word = "running" if job.running else ("cancelled" if job.cancelled else "done")
        if job.error:
            word = "failed"
        imgui.progress_bar(fraction, imgui.ImVec2(-1, 0),
                           f"{job.name}: {word} {work_done(latest)}")
        imgui.text_wrapped(f"elapsed {job.elapsed:.1f} s   {latest.message if latest else ''}")
        target = kind.pipeline if kind.pipeline in viewport_names() else None
        if target is not None and imgui.small_button("Show in viewport"):
            from shadelab.ui.pipelines import set_pipeline

            set_pipeline(state, target)  # the same renderer at the viewport's resolution
    if job.error:
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(panels.ERROR_COLOR, job.error)
        imgui.pop_text_wrap_pos()
    if not state.gpu.attached:
        return False
    width = (imgui.get_content_region_avail().x - 16) / 3
    if state.gpu.texture("job_result") is not None and width > 8:
        ray_tree = kind.pipeline == "raytrace"  # the Whitted tracer keeps a ray tree per pixel
        clicked = _show(state, "job_result", "offline (click: ray tree)"
                        if ray_tree else "offline", width)
        if clicked is not None and ray_tree and not job.running:
            trace_tree(state, clicked)
        imgui.same_line()
        _show(state, "job_raster", f"raster ({kind.raster_shading})", width)
        imgui.same_line()
        _show(state, "job_diff", "|difference|", width)
    if state.offline.comparison:
        c = state.offline.comparison
        imgui.text_wrapped(f"RMSE {c['rmse']:.4g}  max |diff| {c['max_abs']:.4g}  "
                   f"relative RMSE {c['relative_rmse']:.3%}")
        if "flip" in c:
            imgui.same_line()
            imgui.text_wrapped(f"FLIP {c['flip']:.4f}")
            if imgui.is_item_hovered():
                imgui.set_tooltip("NVIDIA FLIP: the perceived difference after exposure "
                                  "(0 = identical, 1 = maximal)")
        imgui.text_colored(panels.DIM_COLOR, f"heat map: red = {c['heat_full_scale']:.3g}")
    if latest is not None and latest.stats and not job.running:
        shown = {k: v for k, v in latest.stats.items()
                 if isinstance(v, (int, float, str, bool))}
        imgui.text_wrapped("  ".join(f"{k}: {v:.4g}" if isinstance(v, float) else f"{k}: {v}"
                                     for k, v in shown.items()))
    if state.offline.radiosity_soup is not None:
        _, state.offline.show_radiosity = imgui.checkbox(
            "Show the radiosity solution in the viewport", state.offline.show_radiosity)
    draw_ray_tree(state)
    return False
