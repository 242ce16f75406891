"""The viewport pipeline's own state: its job, latest image or triangles, and what they were made
of (a dataclass, no GL, no GUI). :mod:`shadelab.ui.pipelines` draws and drives it; it lives
here so that :class:`shadelab.lab.state.AppState` can name its type without an import cycle."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from shadelab import pipelines as _registry

#: The viewer's Pipeline selector: the registry's pipelines with a ``viewport`` place.
PIPELINES = _registry.viewport_names()
LABELS = {name: _registry.get(name).label for name in PIPELINES}
#: The raster ones: (shading, visibility) they write into the scene.
RASTER = {name: _registry.get(name).raster for name in PIPELINES
          if _registry.get(name).raster is not None}
#: The offline ones: the worker's job factory ``f(scene, size)`` (picklable by name).
OFFLINE_NAMES = tuple(name for name in PIPELINES if name not in RASTER)


@dataclass
class PipelineView:
    """The viewport pipeline's job, its latest image or triangles, and what it was made of."""

    runner: object = None                # shadelab.lab.jobs.JobRunner (its own worker)
    applied: str = ""                    # the raster pipeline last written into the scene
    key: object = None                   # what the running/wanted job renders
    wanted: tuple | None = None          # (name, scene, size) waiting for the worker
    name: str = ""                       # pipeline of the current job
    job_scene: object = None
    job_size: tuple = (0, 0)
    version: int = -1
    image_version: int = -1              # the runner's version of the image shown
    image_size: tuple = (0, 0)           # the latest image's (w, h) (coarse levels: smaller)
    soup: np.ndarray | None = None
    shooter: np.ndarray | None = None
    stats: dict = field(default_factory=dict)
    message: str = ""
    history: dict = field(default_factory=dict)
    log: list = field(default_factory=list)     # JobRecord per job (viewport and side panel)
    offline_seen: int = -1                      # the side panel's job already logged
    frame_times: list = field(default_factory=list)   # frames drawn while a job refines
    ray_tree: object = None
    ray_tree_pixel: tuple | None = None
    tree_depth: int = 99                 # ray-tree generations shown
    tree_hover: object = None            # the RayNode hovered in the Ray tree window
    tree_key: object = None              # what the ray tree depends on (ui/pipelines.tree_key)
    raster_key: dict = field(default_factory=dict)
    warm_started: bool = False
    record: object = None                # JobRecord of the viewport's current job
    linear: object = None                # the latest offline image, linear (H, W, 3)
    _offline_record: object = None
    step_mode: bool = False              # radiosity: shots come one press of "Step" at a time
    paused: bool = False

    def ensure_runner(self):
        if self.runner is None:
            from shadelab.lab.jobs import JobRunner

            self.runner = JobRunner()
        return self.runner


def view_of(state) -> PipelineView:
    if state.view.pipeline_view is None:
        state.view.pipeline_view = PipelineView()
    return state.view.pipeline_view


def current(state) -> str:
    """The pipeline shown: an offline ``state.view.pipeline``, else the raster one the scene's
    settings name (the scene is the truth for raster: a lesson step, undo or the Shading
    radio may change them after the choice, and the selector must agree with Shading)."""
    if state.view.pipeline in PIPELINES and state.view.pipeline not in RASTER:
        return state.view.pipeline
    render = state.scene.render
    if render.visibility == "painter":
        return "painter"
    return "gouraud" if render.shading == "gouraud" else "phong"


def set_pipeline(state, name: str) -> None:
    """Switch the viewport's pipeline (the panel, the CLI's --pipeline and lessons call it)."""
    if name not in PIPELINES:
        state.error = f"pipeline '{name}': expected one of {', '.join(PIPELINES)}"
        return
    state.view.pipeline = name
    sync(state)


def sync(state) -> None:
    """Write a newly chosen raster pipeline into the scene (once per choice)."""
    view = view_of(state)
    name = state.view.pipeline
    if name in RASTER and view.applied != name:
        shading, visibility = RASTER[name]
        render = state.scene.render
        if (render.shading, render.visibility) != (shading, visibility):
            render.shading, render.visibility = shading, visibility
            state.mark_edited()
    view.applied = name


# ---------------------------------------------------------------- jobs
