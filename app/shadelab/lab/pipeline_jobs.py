"""The viewport's offline pipelines as worker-process jobs (pure: numpy, no GL, no GUI).

The pipelines themselves live in :mod:`shadelab.pipelines` (one file each, one registry); this
module keeps the viewer's names for them, each ``f(scene, size)`` picklable by reference, so
:class:`shadelab.lab.jobs.JobRunner` runs it in its worker process:

* ray tracing and path tracing render coarse first (:mod:`shadelab.pipelines.progressive`):
  1/8 of the viewport's resolution, then 1/4, 1/2 and full, each a complete picture;
* radiosity shoots patch by patch and sends the Gouraud display triangles after each chunk of
  shots (:meth:`shadelab.pipelines.radiosity.RadiosityPipeline.viewport_job`).
"""

from __future__ import annotations

import time
from typing import Iterator

from shadelab.pipelines import get, viewport_job
from shadelab.pipelines.progressive import LEVELS, held_back, level_size  # noqa: F401
from shadelab.pipelines.radiosity import (  # noqa: F401  (the viewer and tests read them here)
    _RADIOSITY_CACHE,
    RADIOSITY_CHUNK_S,
    _reflectance,
    ff_method,
    pipeline_radiosity,
    radiosity_key,
    soup,
)
from shadelab.progress import Progress
from shadelab.scene.model import Scene
from shadelab.scene.preset import clone_scene

_held_back = held_back


def pipeline_raytrace(scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
    """Whitted at 1/8, 1/4, 1/2 and full resolution (the scene's spp only at full)."""
    return get("raytrace").viewport_job(scene, size)


def pipeline_pathtrace(scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
    """The path tracer at 1/8, 1/4, 1/2 resolution (1 sample), then full at the scene's spp."""
    return get("pathtrace").viewport_job(scene, size)


def pipeline_job(name: str):
    """The viewport job factory ``f(scene, size)`` of registry pipeline ``name``."""
    from functools import partial

    return partial(viewport_job, name)


def warm_kernels(scene: Scene | None, size) -> Iterator[Progress]:
    """Compile or load every numba kernel (Whitted, path tracer, radiosity) on a tiny scene,
    so the first lesson image does not wait for the JIT. Yields once per renderer."""
    from shadelab.scene.preset import load_preset

    tiny = clone_scene(scene) if scene is not None else load_preset("cornell")
    try:
        cornell = load_preset("cornell")
    except Exception:  # a renamed preset must not break the viewer's start
        cornell = tiny
    cornell.radiosity.patches = 24
    cornell.radiosity.solver = "progressive"
    cornell.radiosity.iterations = 2
    stages = (("whitted", lambda: pipeline_raytrace(tiny, (8, 8))),
              ("path tracer", lambda: pipeline_pathtrace(_one_spp(tiny), (8, 8))),
              ("radiosity", lambda: pipeline_radiosity(cornell, None)))
    for i, (name, make) in enumerate(stages):
        t0 = time.perf_counter()
        try:
            for _ in make():
                pass
        except Exception:  # a scene a renderer refuses (no emitter...) still warms the rest
            pass
        yield Progress(None, (i + 1) / len(stages), f"warmed {name}",
                       {f"warm_{name}_s": time.perf_counter() - t0})
    _RADIOSITY_CACHE.clear()


def _one_spp(scene: Scene) -> Scene:
    scene = clone_scene(scene)
    scene.raytrace.spp = 1
    return scene


def warm_pipeline(scene: Scene | None, name: str) -> Iterator[Progress]:
    """The worker's first task when the viewer starts in an offline pipeline: import that
    pipeline's renderer and load (or compile) its kernels on an 8x8 image / 24 patches, while
    the window opens, so the first real job finds them ready. Yields nothing (job id 0)."""
    from shadelab.scene.preset import load_preset

    try:
        if get(name).raster is not None:
            return iter(())  # a GL pipeline: nothing to warm in the worker
        tiny = clone_scene(scene) if scene is not None else load_preset("cornell")
        if name == "radiosity":
            tiny.radiosity.patches = 24
            tiny.radiosity.solver = "progressive"
            tiny.radiosity.iterations = 2
            gen = pipeline_radiosity(tiny, None)
        else:
            gen = viewport_job(name, _one_spp(tiny) if name == "pathtrace" else tiny, (8, 8))
        for _ in gen:
            pass
    except Exception:  # a scene the renderer refuses: its real job reports why
        pass
    _RADIOSITY_CACHE.clear()
    return iter(())
