"""The viewport pipeline's own state: its job, latest image or triangles, and what they were made
of (a dataclass, no GL, no GUI). :mod:`shadelab.ui.pipelines` draws and drives it; it lives
here so that :class:`shadelab.ui.state.AppState` can name its type without an import cycle."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class PipelineView:
    """The viewport pipeline's job, its latest image or triangles, and what it was made of."""

    runner: object = None                # shadelab.ui.jobs.JobRunner (its own worker)
    applied: str = ""                    # the raster pipeline last written into the scene
    key: object = None                   # what the running/wanted job renders
    wanted: tuple | None = None          # (name, scene, size) waiting for the worker
    name: str = ""                       # pipeline of the current job
    job_scene: object = None
    job_size: tuple = (0, 0)
    version: int = -1
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
    raster_key: dict = field(default_factory=dict)
    warm_started: bool = False
    record: object = None                # JobRecord of the viewport's current job
    linear: object = None                # the latest offline image, linear (H, W, 3)
    _offline_record: object = None
    step_mode: bool = False              # radiosity: shots come one press of "Step" at a time
    paused: bool = False

    def ensure_runner(self):
        if self.runner is None:
            from shadelab.ui.jobs import JobRunner

            self.runner = JobRunner()
        return self.runner
