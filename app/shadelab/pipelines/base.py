"""What a pipeline is: :class:`Pipeline` (the protocol) and :class:`BasePipeline` (its defaults).

A pipeline turns a scene into pictures as a progressive job: ``run(scene, size, **options)``
yields :class:`shadelab.progress.Progress`, the last one complete. ``output`` says what that
last step holds: ``"image"`` (``step.image``, (H, W, 3) float32 linear radiance, row 0 at the
top) or ``"triangles"`` (radiosity: ``step.stats["solution"]`` or the display ``soup``, drawn
by the GPU under the live camera). Pure: no GL or GUI import at module level; a pipeline that
needs GL imports it inside ``run``.
"""

from __future__ import annotations

from typing import Any, Iterator, Protocol, runtime_checkable

import numpy as np

from shadelab.progress import Progress
from shadelab.scene.model import Scene

IMAGE = "image"
TRIANGLES = "triangles"


@runtime_checkable
class Pipeline(Protocol):
    """One way to render a scene (ARCHITECTURE.md, "Pipelines")."""

    name: str          # registry name: shadelab.render(pipeline=name), --pipeline name
    label: str         # what the viewer's Pipeline selector shows
    output: str        # IMAGE or TRIANGLES
    options: tuple[str, ...]   # keyword options run() takes (shadelab.render passes these)

    def check(self, scene: Scene, label: str = "") -> None:
        """Refuse a scene this pipeline cannot render: ShadeLabError, one line."""

    def run(self, scene: Scene, size: tuple[int, int], **options: Any) -> Iterator[Progress]:
        """Render progressively; the last Progress is the finished result."""


class BasePipeline:
    """Defaults for a :class:`Pipeline`; subclass it, set the attributes, write ``run``."""

    name = ""
    label = ""
    output = IMAGE
    options: tuple[str, ...] = ()
    default_size = (512, 512)     # shadelab.render's size when none is given
    viewport = 0                  # > 0: offered by the viewer's Pipeline selector, this place
    job_label = ""                # offered by the Offline panel (and --job) under this label
    job_order = 0                 # its place there
    raster: tuple[str, str] | None = None   # (shading, visibility) of a GL raster pipeline
    compare_shading = "phong"     # the raster view the Offline panel compares its image with
    unit = "pixels"               # what the progressive wrapper counts

    def check(self, scene: Scene, label: str = "") -> None:
        return None

    def run(self, scene: Scene, size: tuple[int, int], **options: Any) -> Iterator[Progress]:
        raise NotImplementedError

    @property
    def offline(self) -> bool:
        """Runs on the CPU as a job (everything but the GL raster pipelines)."""
        return self.raster is None

    # -- the coarse-to-fine wrapper's hooks (shadelab.pipelines.progressive)
    def level_state(self, scene: Scene) -> dict:
        """Options shared by every level of one progressive job (e.g. a trace context)."""
        return {}

    def level_options(self, scene: Scene, divisor: int) -> dict:
        """Options of the level at 1/``divisor`` resolution (e.g. 1 sample until full)."""
        return {}

    def work_done(self, step: Progress, size: tuple[int, int], options: dict) -> int:
        """How many ``unit`` the level has done at ``step``."""
        return int(round(step.fraction * size[0] * size[1]))

    # -- turning the finished job into an image (shadelab.render, the CLI)
    def image(self, last: Progress, size: tuple[int, int], **options: Any) -> np.ndarray:
        return last.image

    def info(self, last: Progress, options: dict) -> dict:
        """What ``shadelab.render`` reports in ``Image.info`` besides pipeline and size."""
        return dict(last.stats)

    def job(self, scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
        """The Offline panel's job: full size, the scene's own settings."""
        return self.run(scene, size)

    def viewport_job(self, scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
        """The viewer's job: coarse to fine (see :func:`shadelab.pipelines.progressive`)."""
        from shadelab.pipelines.progressive import progressive

        return progressive(self, scene, size)

    def __repr__(self) -> str:
        return f"<pipeline {self.name}>"

    def __reduce__(self):
        """Pickles by name for registered pipelines, so a job crosses into the worker."""
        from shadelab.pipelines import registry

        if registry.is_builtin(self.name):
            return registry.get, (self.name,)
        # a pipeline registered at run time (a test, a notebook) is unknown to the worker
        # process: refusing to pickle makes the job runner run it in a thread instead
        raise TypeError(f"pipeline '{self.name}' is not built in; it runs in a thread")
