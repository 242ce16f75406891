"""Every way ShadeLab renders a scene, in one registry (ARCHITECTURE.md, "Pipelines").

>>> from shadelab import pipelines
>>> pipelines.names()[:3]
('painter', 'gouraud', 'phong')
>>> pipelines.get("raytrace").run(scene, (64, 48))   # an Iterator[Progress]

One file per pipeline in this package (``raster``: gouraud, phong, flat; ``painter``;
``raytrace``; ``pathtrace``; ``radiosity``; ``reference``), each registering itself with
:func:`register`; :mod:`.progressive` is the coarse-to-fine wrapper the viewer runs image
pipelines through, :func:`run_job` the picklable entry the job runner sends to its worker
process. ``shadelab.render``, the CLI, the viewer and the studies all read this registry.
Pure: nothing here imports GL at module level.
"""

from __future__ import annotations

from typing import Iterator

from shadelab.pipelines.base import IMAGE, TRIANGLES, BasePipeline, Pipeline
from shadelab.pipelines.registry import (
    all_names,
    get,
    job_pipelines,
    names,
    register,
    registered,
    unregister,
    viewport_names,
)
from shadelab.progress import Progress

__all__ = ["IMAGE", "TRIANGLES", "BasePipeline", "Pipeline", "all_names", "get",
           "job_pipelines", "names", "register", "registered", "unregister",
           "viewport_names", "run_job", "viewport_job"]


def run_job(name: str, scene, size) -> Iterator[Progress]:
    """The Offline panel's job of pipeline ``name`` (picklable by reference: the job runner's
    worker process looks the pipeline up by name)."""
    return get(name).job(scene, size)


def viewport_job(name: str, scene, size, **options) -> Iterator[Progress]:
    """The viewport's job of pipeline ``name`` (coarse to fine, or radiosity's shots;
    ``options``: e.g. radiosity's ``step_shots``)."""
    return get(name).viewport_job(scene, size, **options)
