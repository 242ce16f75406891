"""``raytrace``: Whitted recursive ray tracing (:func:`shadelab.raytrace.whitted.iter_raytrace`)."""

from __future__ import annotations

from typing import Iterator

from shadelab.errors import ShadeLabError
from shadelab.pipelines.base import BasePipeline
from shadelab.pipelines.registry import register
from shadelab.progress import Progress
from shadelab.scene.model import Scene


def check_objects(scene: Scene, label: str) -> None:
    if not scene.objects:
        raise ShadeLabError(f"{label}: objects: the scene is empty (expected at least one)")


class RaytracePipeline(BasePipeline):
    name = "raytrace"
    label = "ray tracing (Whitted)"
    options = ("depth", "spp", "fresnel", "backend", "workers")
    default_size = (512, 512)
    viewport = 5
    job_label = "Whitted ray tracer"
    job_order = 2
    unit = "rays"

    def check(self, scene: Scene, label: str = "") -> None:
        label = label or scene.name or "scene"
        check_objects(scene, label)
        if not scene.active_lights():
            raise ShadeLabError(f"{label}: lights: the ray tracer needs at least one "
                                "enabled light")

    def run(self, scene: Scene, size: tuple[int, int], depth: int | None = None,
            spp: int | None = None, fresnel: bool | None = None, backend: str = "auto",
            workers: int = 1, ctx=None) -> Iterator[Progress]:
        from shadelab.raytrace.whitted import iter_raytrace

        return iter_raytrace(scene, size, depth, spp, fresnel, backend, workers=workers,
                             ctx=ctx)

    def level_state(self, scene: Scene) -> dict:
        from shadelab.raytrace.surface import TraceContext

        return {"ctx": TraceContext(scene)}

    def level_options(self, scene: Scene, divisor: int) -> dict:
        return {"spp": scene.raytrace.spp if divisor == 1 else 1}

    def work_done(self, step: Progress, size, options) -> int:
        return int(step.stats.get("rays", 0))


register(RaytracePipeline())
