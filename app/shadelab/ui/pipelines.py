"""The lecture's pipelines as a viewport mode, and the wipe that compares two of them.

``state.view.pipeline`` names one of :data:`PIPELINES`. The raster ones (z-buffer + Gouraud,
z-buffer + Phong, list priority + Phong) set the scene's shading and visibility (an edit, so
undo brings the last one back). The offline ones draw into the main viewport at its
resolution: ray and path tracing coarse first (1/8, 1/4, 1/2, full) and refined in place,
radiosity shot by shot as Gouraud triangles under the live camera. Any edit the image depends
on restarts the job from coarse: the running one is cancelled without waiting, the new one
starts on the first frame the worker is free, and until its first image arrives the last
image stays up. Jobs run in a worker process of their own (:class:`shadelab.lab.jobs.JobRunner`),
so the UI never waits for them.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from imgui_bundle import imgui

from shadelab.lab import pipeline_jobs, prefetch
from shadelab.lab.pipeline_view import (  # noqa: F401  (the viewer reads them here too)
    LABELS,
    OFFLINE_NAMES,
    PIPELINES,
    RASTER,
    PipelineView,
    current,
    set_pipeline,
    sync,
    view_of,
)
from shadelab.lab.state import AppState
from shadelab.scene.preset import clone_scene

OFFLINE = {name: pipeline_jobs.pipeline_job(name) for name in OFFLINE_NAMES}
HOVER_COLOR = 0xFF00FFFF   # the ray hovered in the Ray tree window
RAY_COLORS = {"primary": 0xFFFFFFFF, "reflected": 0xFF30D0FF, "refracted": 0xFFFFB040,
              "shadow": 0xFF40FF40, "blocked": 0xFF4040FF}   # ImGui ABGR
SHOOTER_ABGR = 0xFF10E6FF    # the shooting patch's outline: bright yellow ...
SHOOTER_HALO = 0xFF000000    # ... on a black halo, visible on any wall
PATCH_EDGE_COLOR = (0.02, 0.02, 0.02)


def _process_start() -> float:
    """perf_counter() at this process's start (Linux /proc; else this module's import)."""
    try:
        ticks = os.sysconf("SC_CLK_TCK")
        start = int(Path("/proc/self/stat").read_text().rsplit(")", 1)[1].split()[19]) / ticks
        uptime = float(Path("/proc/uptime").read_text().split()[0])
        return time.perf_counter() - (uptime - start)
    except (OSError, ValueError, IndexError):
        return time.perf_counter()


PROCESS_START = _process_start()


def since_start(t: float) -> float:
    return round(t - PROCESS_START, 3)


@dataclass
class JobRecord:
    """One job's figures for ``--bench-json``: seconds from process start."""

    name: str
    size: tuple
    started_s: float
    first_image_s: float | None = None
    done_s: float | None = None
    reused_form_factors: bool | None = None
    prefetched: bool | None = None      # adopted from the lesson's prefetch (lab/prefetch.py)
    first_full_s: float | None = None   # a full-size level's first whole pass shown (one
                                        # sample per pixel of the path tracer)

    def as_dict(self) -> dict:
        return {"name": self.name, "size": list(self.size), "started_s": self.started_s,
                "first_image_s": self.first_image_s, "done_s": self.done_s,
                **({} if self.first_full_s is None else {"first_full_s": self.first_full_s}),
                **({} if self.reused_form_factors is None
                   else {"form_factors_reused": self.reused_form_factors}),
                **({} if self.prefetched is None else {"prefetched": self.prefetched})}


def job_key(state: AppState, name: str, size: tuple[int, int]) -> tuple:
    """What an offline image depends on: radiosity is view-independent (no camera, no size:
    the edit key of the objects, materials and radiosity settings only); the others key on the
    whole scene by its edit counter and which scene it is, as the viewport does
    (:meth:`shadelab.ui.app.Viewer.frame_key`)."""
    scene = state.scene
    if name == "radiosity":
        return (name, scene.edit_key("objects", "materials", "radiosity"), scene.base_dir)
    spp = state.offline.spp if name == "pathtrace" else scene.raytrace.spp
    return (name, id(scene), state.scene_version, scene.version, size, spp)


def tree_key(scene) -> tuple:
    """What a picked ray tree depends on: the scene (which one) and its objects, materials,
    lights and ray-tracing settings, not the camera (the tree is in world space)."""
    return (scene.base_dir, scene.edit_key("objects", "materials", "lights", "raytrace"))


def scene_for(state: AppState, name: str):
    scene = clone_scene(state.scene)
    if name == "pathtrace":
        scene.raytrace.spp = max(int(state.offline.spp), 1)
    return scene


def poll(state: AppState, name: str, size: tuple[int, int]) -> None:
    """Restart the job when what it renders changed; take its newest result."""
    view = view_of(state)
    runner = view.ensure_runner()
    key = job_key(state, name, size)
    if key != view.key:
        view.key = key
        if view.tree_key != tree_key(state.scene):
            # the tree is in world space: a camera move or a resize keeps it, an edit of what
            # the rays hit or the tracer's settings clears it
            view.ray_tree = view.ray_tree_pixel = view.tree_hover = view.tree_key = None
        if _adopt_prefetch(state, name, size):
            _take(state)
            return
        view.wanted = (name, scene_for(state, name), size)
        # no wait: the new job starts once this one stops; a warm-up stops at its next stage
        # (one renderer's kernels) and is never killed mid-compile
        if view.name == "warm-up":
            runner.cancel(kill_after=None)
        else:
            runner.cancel()
    if view.wanted is not None and not runner.running and not view.paused:
        _start(state, *view.wanted)
        view.wanted = None
    _take(state)


def _prefetch_key(state: AppState, index: int, name: str, size) -> tuple:
    return prefetch.step_key(state.walk.lesson, index, name, size, state.offline.spp)


def _adopt_prefetch(state: AppState, name: str, size) -> bool:
    """The lesson step just arrived unedited and its job was prefetched: the viewport takes
    that runner, finished or still refining (its own idle runner goes to the prefetch)."""
    run, pf = state.walk.lesson, state.walk.prefetch
    if pf is None or pf.key is None or not prefetch.unedited(run, state):
        return False
    if run.step is None or run.step.pipeline != name or view_of(state).step_mode:
        return False
    view = view_of(state)
    scene, job_size = pf.scene, pf.size
    old = view.runner
    runner = pf.take(_prefetch_key(state, run.index, name, size), give_back=old)
    if runner is None:
        return False
    if old is not None:
        old.cancel()
    if view.record is not None and view.record.done_s is None and old is not None:
        view.record.done_s = since_start(old.finished or time.perf_counter())
    view.runner, view.wanted = runner, None
    view.name, view.job_scene, view.job_size = name, scene, job_size
    view.version = view.image_version = -1
    view.record = JobRecord(f"viewport {name}", tuple(size), since_start(time.perf_counter()),
                            prefetched=True)
    view.log.append(view.record)
    view.stats = {}
    return True


def prefetch_tick(state: AppState, size: tuple[int, int]) -> None:
    """Once a frame with a lesson open: render the next step's offline pipeline ahead of
    time when the current step is settled; drop a prefetch that no longer matches."""
    run = state.walk.lesson
    pf = state.walk.prefetch
    if run is None and pf is None:
        return
    if pf is None:
        pf = state.walk.prefetch = prefetch.Prefetch()
    pf.enabled = state.walk.prefetch_enabled
    nxt = prefetch.next_offline(run, OFFLINE)
    wanted = None
    if nxt is not None:
        index, name = nxt
        wanted = (_prefetch_key(state, index, name, size), index, name, size)
    current_busy = current(state) in OFFLINE and busy(state)
    pf.tick(wanted, current_busy, lambda w: _start_prefetch(state, pf, *w[1:]))
    record, runner = pf.record, pf.runner
    if record is not None and runner is not None and pf.key is not None:
        latest, _ = runner.snapshot()
        if record.first_image_s is None and latest is not None and (
                latest.image is not None or "soup" in (latest.stats or {})):
            record.first_image_s = since_start(time.perf_counter())
        if record.done_s is None and runner.started and not runner.running:
            record.done_s = since_start(runner.finished or time.perf_counter())


def _start_prefetch(state: AppState, pf, index: int, name: str, size) -> None:
    from shadelab.lab.jobs import JobRunner
    from shadelab.lab.lesson_file import step_scene

    step = state.walk.lesson.lesson.steps[index]
    try:
        scene = step_scene(step)
    except Exception as exc:   # go_to will say it in words when the step is reached
        pf.key = None
        state.error = f"lesson step {index + 1}: {exc}"
        return
    if name == "pathtrace":
        scene.raytrace.spp = max(int(state.offline.spp), 1)
    if pf.runner is None:
        pf.runner = JobRunner()
    pf.runner.prepare = SRGB_OFF_THREAD
    pf.scene, pf.size = scene, tuple(size)
    factory = OFFLINE[name]
    pf.record = JobRecord(f"prefetch {name} (step {index + 1})", tuple(size),
                          since_start(time.perf_counter()))
    view_of(state).log.append(pf.record)
    pf.runner.start(name, lambda: factory(scene, size), call=(factory, scene, size))


def _start(state: AppState, name: str, scene, size) -> None:
    view = view_of(state)
    factory = OFFLINE[name]
    if view.record is not None and view.record.done_s is None:
        view.record.done_s = since_start(view.runner.finished or time.perf_counter())
    view.name, view.job_scene, view.job_size = name, scene, size
    view.version = view.image_version = -1
    view.record = JobRecord(f"viewport {name}", tuple(size), since_start(time.perf_counter()))
    view.log.append(view.record)
    view.stats = {}
    if name == "radiosity" and view.step_mode:
        gate = _StepGate(view.runner._cancel)
        view.stats["gate"] = gate
        view.runner.start(name, lambda: gate.wrap(factory(scene, size, step_shots=1)))
    else:
        view.runner.start(name, lambda: factory(scene, size), call=(factory, scene, size))


class _StepGate:
    """Runs a radiosity job one shot per :meth:`step` (a thread job; the UI presses Step): the
    first shot comes at once, each press lets the next one through."""

    def __init__(self, cancelled) -> None:
        import threading

        self.allowed = threading.Semaphore(1)
        self.cancelled = cancelled          # the runner's cancel event

    def step(self) -> None:
        self.allowed.release()

    def wrap(self, gen):
        for item in gen:
            if "shots" not in (item.stats or {}):   # meshing, form factors: no shot to wait for
                yield item
                continue
            while not self.allowed.acquire(timeout=0.05):
                if self.cancelled.is_set():
                    return
            yield item


class SrgbOffThread:
    """The display conversion of a job's images (exposure, clip, sRGB, bottom-up RGBA) in
    the job runner's listener thread, for the newest image only (``JobRunner.prepare``):
    on the UI thread ``to_srgb8`` of a 1920x858 path-traced image took ~0.2 s per update,
    and the viewer drew 5 fps while the path tracer refined. ``exposure``: the viewer's,
    written by the UI thread every frame; each result names the exposure it used."""

    exposure = 1.0

    def __call__(self, step) -> tuple:
        from shadelab.shading.conventions import to_srgb8

        exposure = self.exposure
        image = np.asarray(step.image, np.float32)
        h, w = image.shape[:2]
        rgba = np.empty((h, w, 4), np.uint8)   # the texture's own layout: no copy on upload
        rgba[..., :3], rgba[..., 3] = to_srgb8(image, exposure)[::-1], 255
        return exposure, rgba, image


SRGB_OFF_THREAD = SrgbOffThread()


def _show_image(state: AppState, view, image: np.ndarray, srgb_bottom_up=None) -> None:
    """Upload the display of a linear image (bottom-up sRGB rows, RGB or RGBA; converted here
    when not given)."""
    if srgb_bottom_up is None:
        from shadelab.shading.conventions import to_srgb8

        srgb_bottom_up = to_srgb8(image, state.scene.render.exposure)[::-1]
    state.gpu.upload("pipeline", srgb_bottom_up)
    view.image_size = (image.shape[1], image.shape[0])
    view.linear = image


def _take_words(view, message: str, stats: dict) -> None:
    view.message = message
    view.stats = {k: v for k, v in stats.items() if k not in ("soup", "history")} \
        | ({"gate": view.stats["gate"]} if "gate" in view.stats else {})
    if "history" in stats:
        view.history = stats["history"]


def _take(state: AppState) -> None:
    """The job's newest Progress into the view. A process job's images come converted by
    the runner's listener thread (:class:`SrgbOffThread`), each with its own Progress's
    words, so the view never says "done" over an older image; a thread job's (and a
    Progress without an image: radiosity's triangles, meshing) are taken here."""
    view = view_of(state)
    runner = view.runner
    if getattr(runner, "prepare", False) is None:   # a JobRunner (tests pass stand-ins)
        runner.prepare = SRGB_OFF_THREAD
    SRGB_OFF_THREAD.exposure = float(state.scene.render.exposure)
    latest, version = runner.snapshot()
    record = view.record
    if record is not None and record.done_s is None and runner.started \
            and not runner.running:   # (an adopted prefetch may have finished before)
        record.done_s = max(record.started_s,
                            since_start(runner.finished or time.perf_counter()))
    off_thread = getattr(runner, "prepare", None) is not None \
        and getattr(runner, "in_process", False)
    got_image, image_stats, taken = False, {}, {}
    prepared = getattr(runner, "prepared", None) if off_thread else None
    if prepared is not None and prepared[0] > view.image_version:
        version_p, (exposure, rgba, image), stats_p, message_p = prepared
        view.image_version = version_p
        # converted again here only if the exposure changed since
        _show_image(state, view, image, rgba if exposure == state.scene.render.exposure
                    else None)
        got_image, image_stats = True, stats_p
        if version_p > view.version:
            view.version = version_p
            _take_words(view, message_p, stats_p)
            taken = stats_p
    if latest is not None and version > view.version \
            and not (off_thread and latest.image is not None):
        view.version = version
        stats = taken = latest.stats or {}
        _take_words(view, latest.message, stats)
        if latest.image is not None:   # a thread job's image
            _show_image(state, view, np.asarray(latest.image, np.float32))
            view.image_version = version
            got_image, image_stats = True, stats
        if "soup" in stats:
            view.soup = stats["soup"]
            view.shooter = stats.get("shooter")
            got_image, image_stats = True, stats
    stats = image_stats
    if record is not None and got_image and record.first_image_s is None:
        record.first_image_s = since_start(time.perf_counter())
    if record is not None and got_image and record.first_full_s is None \
            and stats.get("level") == 1 and "size" in stats \
            and stats.get("level_work", 0) >= stats["size"][0] * stats["size"][1]:
        record.first_full_s = since_start(time.perf_counter())
    if record is not None and "form_factors_reused" in taken:
        record.reused_form_factors = bool(taken["form_factors_reused"])


def track_side_panel_job(state: AppState) -> None:
    """Log the offline panel's job (``--job NAME``) for ``--bench-json`` too."""
    view, job = view_of(state), state.offline.runner
    if job is None or not job.started:
        return
    if view.offline_seen != job._job_id:
        view.offline_seen = job._job_id
        view.log.append(JobRecord(job.name, tuple(state.offline.size_px),
                                  since_start(job.started)))
        view._offline_record = view.log[-1]
    record = view._offline_record
    latest, _ = job.snapshot()
    if record.first_image_s is None and latest is not None and latest.image is not None:
        record.first_image_s = since_start(time.perf_counter())
    if record.done_s is None and not job.running:
        record.done_s = since_start(job.finished or time.perf_counter())


def busy(state: AppState) -> bool:
    """An offline pipeline is still refining (``--frames`` counts after it)."""
    view = state.view.pipeline_view
    if view is None or state.view.pipeline not in OFFLINE or view.runner is None:
        return False
    return view.wanted is not None or view.runner.running or view.version < 0


def warming(state: AppState) -> bool:
    """The start-up warm-up job (the worker process importing and loading the offline
    kernels, on the other core) has not finished yet."""
    view = state.view.pipeline_view
    return view is not None and view.name == "warm-up" and view.runner is not None \
        and (view.runner.running or not view.runner.started)


def warm(state: AppState) -> None:
    """Compile or load the offline kernels in the pipeline worker (viewer start-up)."""
    view = view_of(state)
    if view.warm_started:
        return
    view.warm_started = True
    runner = view.ensure_runner()
    if runner.worker is not None:
        runner.worker.ensure()   # spawn now: the process imports while the window opens
    if state.view.pipeline in OFFLINE:
        if runner.worker is not None:  # import + load that pipeline's kernels before frame 3
            runner.worker.tasks.put((0, pipeline_jobs.warm_pipeline, clone_scene(state.scene),
                                     state.view.pipeline))
        return
    scene = clone_scene(state.scene)
    view.name = "warm-up"
    view.record = JobRecord("warm-up", (8, 8), since_start(time.perf_counter()))
    view.log.append(view.record)
    runner.start("warm-up", lambda: pipeline_jobs.warm_kernels(scene, None),
                 call=(pipeline_jobs.warm_kernels, scene, None))


def bench_report(state: AppState) -> dict:
    """``jobs`` (name, first_image_s, done_s from process start) and the refining fps."""
    view = state.view.pipeline_view
    if view is None:
        return {}
    track_side_panel_job(state)
    report: dict = {"jobs": [r.as_dict() for r in view.log]}
    times = np.diff(np.asarray(view.frame_times)) if len(view.frame_times) > 2 else []
    if len(times):
        report["refining_fps_median"] = float(1.0 / np.median(times))
        report["refining_frames"] = len(view.frame_times)
    return report


# ---------------------------------------------------------------- drawing


def patch_edges(soup: np.ndarray) -> np.ndarray:
    """Each display triangle's edges (the patches: two triangles per quad patch, the
    diagonal included) as dark segments."""
    tri = soup[:, :3].reshape(-1, 3, 3)
    starts = tri.reshape(-1, 3)
    ends = np.roll(tri, -1, axis=1).reshape(-1, 3)
    out = np.empty((len(starts), 2, 6), np.float32)
    out[:, 0, :3], out[:, 1, :3], out[:, :, 3:] = starts, ends, PATCH_EDGE_COLOR
    return out.reshape(-1, 6)


def shooter_outline(scene, size: tuple[int, int], polygon: np.ndarray) -> np.ndarray | None:
    """The shooting patch's corners in viewport pixels (4, 2), drawn as a thick bright
    outline over everything (None when a corner is behind the eye)."""
    xy, front = project(scene, size, np.asarray(polygon, float).reshape(-1, 3))
    if not front.all():
        return None
    return xy


def label(draw_list, pos, text: str, wrap: float = -1.0) -> None:
    """White text on a dark box; wrapped at ``wrap`` pixels when given (> 0)."""
    size = imgui.calc_text_size(text, False, wrap)
    draw_list.add_rect_filled(imgui.ImVec2(pos.x - 4, pos.y - 2),
                              imgui.ImVec2(pos.x + size.x + 4, pos.y + size.y + 2), 0xB0000000)
    draw_list.add_text(imgui.get_font(), imgui.get_font_size(), pos, 0xFFFFFFFF, text,
                       max(wrap, 0.0))


def status_line(state: AppState) -> str:
    view = view_of(state)
    name = current(state)
    if name not in OFFLINE:
        return LABELS[name]
    runner = view.runner
    word = "refining" if runner is not None and runner.running else ""
    if view.wanted is not None:
        word = "restarting"
    if runner is not None and runner.error:
        word = f"failed: {runner.error}"
    elapsed = runner.elapsed if runner is not None else 0.0
    message = view.message
    if name == "radiosity" and "shots" in view.stats and not (runner and runner.error):
        # one short line over the room's ceiling, where the light patch shoots first
        unshot = view.history.get("unshot") or [float("nan")]
        done = "done: " if view.stats.get("done") else ""
        message = f"{done}shot {view.stats['shots']}, unshot {100.0 * unshot[-1]:.2f} %"
    return f"{LABELS[name]}: {word}  {message}  {elapsed:.1f} s"


def pick_ray_tree(state: AppState, name: str, pixel, display_size) -> None:
    """A click in the ray-traced viewport picks that pixel's ray tree."""
    view = view_of(state)
    if name != "raytrace" or view.job_scene is None:
        return
    w, h = view.job_size
    x = min(int(pixel[0] * w / display_size[0]), w - 1)
    y = min(int(pixel[1] * h / display_size[1]), h - 1)
    try:
        from shadelab.raytrace.tree import trace_pixel_tree

        view.ray_tree = trace_pixel_tree(view.job_scene, (w, h), x, y)
        view.ray_tree_pixel = (x, y)
        view.tree_key = tree_key(view.job_scene)   # a copy has its original's edit key
        view.tree_hover = None
        view.tree_depth = 99
    except Exception as exc:  # shown in the app; the session goes on
        state.error = f"ray tree of pixel {(x, y)}: {exc}"


def project(scene, size: tuple[int, int], points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Screen (x, y) in [0, size] of world points and whether each is in front of the eye."""
    from shadelab.scene.camera import camera_basis, tan_half_fov_y

    forward, right, up = camera_basis(scene.camera)
    rel = np.asarray(points, float) - np.asarray(scene.camera.eye, float)
    z = rel @ forward
    aspect = size[0] / max(size[1], 1)
    tan_half = tan_half_fov_y(scene.camera, aspect)
    zs = np.maximum(z, 1e-9)
    x = (rel @ right) / (zs * tan_half * aspect)
    y = (rel @ up) / (zs * tan_half)
    return np.stack([(x + 1) * 0.5 * size[0], (1 - y) * 0.5 * size[1]], axis=1), z > 0


def tree_segments(root, miss_length: float, max_depth: int = 99) -> list[tuple]:
    """(kind, start, end, node, generation) of every ray of the tree up to ``max_depth``."""
    out = []
    for _, node in root.flatten():
        if node.depth > max_depth:
            continue
        end = node.end if node.end is not None else node.origin + miss_length * node.direction
        kind = "blocked" if node.kind == "shadow" and node.shadow < 1.0 else node.kind
        out.append((kind, np.asarray(node.origin), np.asarray(end), node))
    return out


def object_label(scene, index: int) -> str:
    """'name (material)' of an object, as the lecture would say it."""
    if not 0 <= index < len(scene.objects):
        return "background"
    obj = scene.objects[index]
    return f"{obj.name or obj.shape} ({obj.material})"


def draw_ray_tree(state: AppState, draw_list, origin, display_size) -> None:
    """The picked pixel's ray tree over the ray-traced image: thick lines by kind, hit
    points labelled with object and material."""
    view = view_of(state)
    scene = view.job_scene
    from shadelab.geometry.mesh import scene_meshes
    from shadelab.lab.overlays import scene_diagonal

    miss = 0.3 * scene_diagonal(scene_meshes(scene))
    segments = tree_segments(view.ray_tree, miss, view.tree_depth)
    thick = 4.0 if state.view.presenter else 3.0
    for kind, start, end, node in segments:
        pts, front = project(scene, display_size, np.stack([start, end]))
        if not front[1]:
            continue
        a = imgui.ImVec2(origin.x + pts[0, 0], origin.y + pts[0, 1])
        b = imgui.ImVec2(origin.x + pts[1, 0], origin.y + pts[1, 1])
        if front[0]:   # (a primary ray starts at the eye: it projects to its end point)
            draw_list.add_line(a, b, RAY_COLORS[kind], thick)
        if node.end is not None and node.kind != "shadow":
            draw_list.add_circle_filled(b, thick + 2, RAY_COLORS[kind])
            label(draw_list, imgui.ImVec2(b.x + 8, b.y - 8),
                   f"{node.kind} d{node.depth}: {object_label(scene, node.object)}")
        if node is view.tree_hover:   # hovered in the Ray tree window
            if front[0]:
                draw_list.add_line(a, b, HOVER_COLOR, 2.5 * thick)
            draw_list.add_circle(b, 3 * thick, HOVER_COLOR, 0, thick)
